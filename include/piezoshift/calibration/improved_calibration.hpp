#pragma once
// Calibration of the improved controller (control/semi_closed_loop.hpp, kind = kImproved; issue
// 12), on the twin through the shipping loop (rig/bench.hpp), each step on a bench of its
// own:
//   0.   the inner loop identified open loop at the loop's rate, and the PID gains stages 1 to 3
//        hold with chosen on it: the paper's when their margins there suffice, else scaled down
//        (holding_gains.hpp: at 10 kHz a thicker plate's mode made the paper's
//        re-expressed gains unstable and stage 2 tripped the supervisor)       seed + 6
//   1-3. the paper's procedure (calibration_procedure.hpp): A and p, the gauge-to-plate map the
//        improved controller keeps as its feedforward          seeds seed .. seed + 2
//   4.   the channel models: an open-loop excitation (a major loop, reversal curves, steps held
//        for creep, small steps at mid-travel), the commands and gauge readings recorded every
//        tick and fitted (hysteresis_identification.hpp)        seed + 4
//   5.   the plate's mode: a small open-loop step, the interferometer's dynamic samples fitted by
//        Prony's method; it sets the shaper's taps                  seed + 5
//   5b.  the same step with the interferometer at 10 kHz, the mode unfolded, for the verdict on
//        the loop's rate (rate_verdict.hpp); not used by the controller    seed + 8
//   6.   the correction loop's integral gain for a chosen bandwidth, and the rate limit from the
//        amplifier's slew (its current limit into the stack's capacitance).
//   7.   large moves tried both ways on the plant: the 11 um step with the slew path
//        and with the shaper alone, the plate's overshoot read by the interferometer's dynamic
//        samples; the slew path kept when they read under half the 1 % overshoot allowed or no more
//        than the shaper alone's, else turned off. The slew's stop leaves a ring whose phase is
//        set by the plate's true mode, which the 1 kHz fold of stage 5 does not give
//        (docs/control.md, "Large moves")                           seed + 7
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "piezoshift/calibration/calibration_procedure.hpp"
#include "piezoshift/calibration/holding_gains.hpp"
#include "piezoshift/calibration/hysteresis_identification.hpp"
#include "piezoshift/calibration/mode_identification.hpp"
#include "piezoshift/calibration/rate_verdict.hpp"

namespace piezoshift::calibration {

struct ImprovedCalibrationOptions {
  CalibrationOptions paper{};  //!< the static map's stages (A, p), as the paper's procedure
  HysteresisFitOptions model{};
  //! The correction loop's crossover: low, so the gauges' noise stays out of the plate (a 1 ms
  //! exposure's jitter grows with its square root), high enough to follow creep the model misses.
  double correction_bandwidth_Hz = 5.0;
  //! The boost's ceiling (large model errors, e.g. after a long move), as a bandwidth: 50 Hz
  //! keeps 11 dB and 65 deg on the identified loop at 1 kHz.
  double boost_bandwidth_Hz = 50.0;
  double slew_margin = 0.7;  //!< the rate limit as this fraction of the amplifier's slew
  //! Large moves: the command's step per tick as this fraction of the slew the supervisor passes
  //! (its max_slew_V_per_s, below the amplifier's), so the amplifier slews through most of each
  //! tick (docs/control.md, "Large moves"); 0 turns the slew path off.
  double large_move_slew_fraction = 0.98;
  //! and the slew stops this far (SGS um) before the target: above the ring the stop leaves
  //! (0.2 to 0.3 um of plate on the plants of docs/compare.md), so it stays below the target.
  double large_move_approach_um = 1.0;
  double mode_step_from_um = 5.0;  //!< stage 5: open-loop command held, then
  double mode_step_um = 0.3;       //!< stepped by this
  double mode_record_s = 0.03;     //!< and the interferometer recorded this long
  //! Stage 5b: the interferometer's dynamic rate for the unfolded mode (an XL-80 samples up to
  //! 50 kHz), and the lambda/8 step's bound the verdict judges the loop's rate against.
  double verdict_interferometer_rate_Hz = 10000.0;
  double verdict_phase_step_target_s = 5e-3;
  HoldingGainsOptions holding{};  //!< stage 0
  //! Stage 7: Table 4's 11 um step (the paper's), from 0 after large_move_pre_s, recorded for
  //! large_move_record_s; the slew path kept when the samples read its overshoot under
  //! large_move_keep_below_pct: half the 1 % overshoot allowed, because the 1 kHz samples read a
  //! ring's peak low, at 0.17 to 0.94 of the plate's true overshoot (seed 1, six plants:
  //! docs/control.md), or when they read it no larger than the shaper alone's.
  double large_move_trial_um = 11.0;
  double large_move_pre_s = 0.3;
  double large_move_record_s = 0.2;
  double large_move_keep_below_pct = 0.5;
  //! Stages 5 and 7 read the laser interferometer's dynamic samples (the XL-80's, at the loop's
  //! rate). false: there is none (the calibration from fringes: a camera's 78 frames/s
  //! cannot sample the plate's kHz mode): no mode nulled (shaped false, the rate limit alone)
  //! and the slew path as stage 6 designs it, not tried.
  bool dynamic_interferometer = true;
};

//! Stage 7's trial: the plate's overshoot of the large move each way, as the interferometer's
//! dynamic samples read it (its peak over its final level, the last tenth's mean) [%].
struct LargeMoveTrial {
  bool tried = false;     //!< false: the slew path was off already, or the trial step saturated
  std::string not_tried;  //!< why not ("": tried)
  double slew_um_per_s = 0.0;  //!< the slew path tried (stage 6's command_slew_um_per_s)
  double slew_overshoot_pct = 0.0;
  double shaper_overshoot_pct = 0.0;
  bool slew_kept = false;
};

struct ImprovedCalibrationOutcome {
  control::SemiClosedLoopParams controller;  //!< the improved controller to load
  HoldingGains holding;                      //!< stage 0: what stages 1 to 3 held with
  CalibrationOutcome static_map;             //!< stages 1 to 3 as the paper's procedure ran them
  std::array<HysteresisFit, 3> model{};
  //! The plate's mode as the interferometer's dynamic samples show it, and whether the shaper
  //! uses it.
  PlateModeEstimate mode;
  bool shaped = false;
  //! Stage 5b: the mode unfolded (stage 5's when the interferometer already ran at the verdict's
  //! rate), and the verdict on the loop's rate it gives (empty without an interferometer).
  PlateModeEstimate unfolded_mode;
  RateVerdict rate_verdict;
  //! The excitation as recorded (stage 4), per tick: t_s, command and gauge per channel.
  std::vector<double> record_t_s;
  std::array<std::vector<double>, 3> record_command_um, record_gauge_um;
  //! The ring-down (stage 5): the interferometer's mean of P1..P3 at its rate, t_s from the step.
  std::vector<double> mode_record_t_s, mode_record_um;
  LargeMoveTrial large_move;  //!< stage 7
};

struct ImprovedDesign {
  control::SemiClosedLoopParams controller;
  bool shaped = false;  //!< the shaper nulls the mode (false: no mode, or one it cannot place)
};

//! base supplies the sample time, limits and scaling. Throws rig::ProcedureFailed when a
//! stage trips the supervisor or stage 0 finds no gains that hold the plant, FitError when a fit
//! fails.
ImprovedCalibrationOutcome calibrate_improved(const config::ProjectConfig& config,
                                              const control::SemiClosedLoopParams& base,
                                              std::uint64_t seed,
                                              const ImprovedCalibrationOptions& options = {},
                                              const rig::Progress& progress = {});

//! Stages 1 to 3 run by the caller: the paper's controller (gains, A, p) calibrated with the
//! options given (their holding_gains set when stage 0 scaled the paper's), or
//! rig::ProcedureFailed with the stage's reason.
using StaticMapStages =
    std::function<control::SemiClosedLoopParams(const CalibrationOptions& static_map)>;

//! The same with stages 1 to 3 as static_map runs them (the calibration from fringes: the
//! Fizeau instead of the XL-80, instrument/fringe_calibration.hpp); the outcome's static_map is
//! then empty, the caller has its own.
ImprovedCalibrationOutcome calibrate_improved(const config::ProjectConfig& config,
                                              const control::SemiClosedLoopParams& base,
                                              std::uint64_t seed,
                                              const ImprovedCalibrationOptions& options,
                                              const StaticMapStages& static_map);

//! Stage 6 alone, from the other stages' results however they were obtained (the twin above, or
//! recorded bench files through `piezoshift fit improved`): paper supplies A, p, the scaling, the
//! limits and the loop's sample time; config the amplifier's slew (its current limit into the
//! stacks' capacitance). The shaper nulls the mode when the loop runs at the rate it was sampled
//! at, or when it was sampled unfolded at least as fast as the loop.
ImprovedDesign design_improved_controller(const config::ProjectConfig& config,
                                          const control::SemiClosedLoopParams& paper,
                                          const std::array<HysteresisFit, 3>& model,
                                          const PlateModeEstimate& mode,
                                          const ImprovedCalibrationOptions& options = {});

//! The command (um) of the stage-4 excitation at time t_s, and its duration.
double improved_excitation_um(double t_s);
double improved_excitation_duration_s();

}  // namespace piezoshift::calibration
