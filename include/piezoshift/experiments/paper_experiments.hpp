#pragma once
// The paper's four experiments (Section 4), each on a fresh bench (the twin at rest, the
// controller given), so each is reproducible on its own from its seed. The unit is the same in
// every one (its parameters come from the configuration); the seed changes only the session:
// noise, the phase of the lab's temperature cycle, the interferometer's scale error.
//
// Travel range (4.1)   open loop: all AO at 10 V (150 V) for open_loop_settle_s, then one static
//                      reading; travel = mean of P1..P3.
//                      semi-closed loop: Z_d from start_um upwards in increment_um, hold_s each
//                      (from coarse_step_um lower, again, while start_um is not tracked),
//                      one static reading; a level is tracked when no PID is at its output limit
//                      and |mean(P) - Z_d| <= tolerance_um; travel = the last level tracked
//                      before the first that is not. Then the single-move travel: from that
//                      level down, the first that one move from rest reaches and tracks (what
//                      `serve` advertises: creeping up lets creep lower the drive a level needs),
//                      and the lowest level one move down from there reaches (the stacks'
//                      hysteresis at 0 V leaves them above zero after a descent).
// Step response (4.1)  Z_d = 0 for pre_s, then a step to step_um, record_s recorded with the
//                      interferometer's dynamic mode (1 kHz); metrics_step_response.hpp on the
//                      mean of P1..P3; and the true plate's overshoot between the ticks (the
//                      twin's physics-rate truth).
// Linearity (4.2)      Z_d = 0, 1, ..., 11 um, step_hold_s each, one static (1 s) sample per
//                      second; the displacement of a level is the mean of its samples after the
//                      first skip_samples; metrics_linearity.hpp. The same protocol also runs on
//                      a grid the calibration never saw (increment_um = 0.25) and downwards.
// Repeatability (4.3)  moves times: Z_d = 0 for rest_s, Z_d = target for settle_s, one static
//                      reading; z_i = mean of P1..P3; metrics_repeatability.hpp (Eq. 9).
//
// Every experiment runs on the shipping loop (bench.hpp), supervisor included, and says whether
// it is valid (validity.hpp). Not valid: the supervisor tripped (travel: except at the level that
// ends the search); a PID at its output limit where a value is measured; the step's final value
// further than target_tolerance_um from the step, or no settling within the record; a linearity
// level further than reach_tolerance_um from Z_d; a repeatability reading further than
// target_tolerance_um from the target; no semi-closed level tracked at all.
#include <cstdint>
#include <vector>

#include "piezoshift/config/project_config.hpp"
#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/experiments/metrics_linearity.hpp"
#include "piezoshift/experiments/metrics_repeatability.hpp"
#include "piezoshift/experiments/metrics_step_response.hpp"
#include "piezoshift/rig/bench.hpp"
#include "piezoshift/rig/progress.hpp"
#include "piezoshift/rig/validity.hpp"

namespace piezoshift::experiments {

struct TravelRangeOptions {
  double open_loop_settle_s = 5.0;
  double start_um = 10.0;
  double increment_um = 0.1;
  double max_um = 16.0;  //!< give up above this (the nominal stroke)
  double hold_s = 1.0;
  double tolerance_um = 0.05;
  double min_increment_um = 0.05;  //!< grid of the lowest level reached from the top
  //! When start_um is not tracked, the search starts again this much lower (down to > 0).
  double coarse_step_um = 1.0;
  rig::BenchOptions bench{};  //!< feedback (gauges or oracle) and the supervisor's limits
};

struct TravelRangeResult {
  double open_loop_um = 0.0;
  control::Vec3 open_loop_points_um{};
  double semi_closed_um = 0.0;  //!< 0 when even start_um was not tracked
  //! The largest level, from semi_closed_um down in increment_um, that one move from rest at 0
  //! reaches and tracks (a fresh session, seed + 2): the travel a user can command.
  double single_move_um = 0.0;
  //! The lowest level, from 0 up in min_increment_um, that one move down from single_move_um
  //! reaches and tracks (a fresh session, seed + 3).
  double single_move_min_um = 0.0;
  std::vector<double> desired_um;      //!< every level tried
  std::vector<double> tracked_levels;  //!< the levels tracked, in order (semi_closed_um last)
  std::vector<double> measured_um;     //!< mean of P1..P3
  std::vector<int> saturated_mask;     //!< controller saturation at the end of each level
  rig::Validity validity;              //!< see validity.hpp and the header comment
  double simulated_time_s = 0.0;
};

struct StepExperimentOptions {
  double step_um = 11.0;
  double pre_s = 0.5;
  double record_s = 1.0;
  double band_pct = 2.0;
  double band_nm = 10.0;
  //! Final value (mean of the record's last samples) within this of the step, else not reached.
  //! The travel search's tracking tolerance.
  double target_tolerance_um = 0.05;
  rig::BenchOptions bench{};  //!< feedback (gauges or oracle) and the supervisor's limits
};

struct StepExperimentResult {
  std::vector<double> time_s;       //!< from the step instant
  std::vector<double> measured_um;  //!< interferometer, dynamic mode, mean of P1..P3
  std::vector<double> desired_um;
  std::vector<double> truth_um;  //!< the twin's true mean of P1..P3 at each tick
  StepResponseMetrics metrics;
  //! Overshoot of the true plate over every physics step, between the ticks included [% of the
  //! step]: what the 1 kHz samples can miss.
  double truth_overshoot_pct = 0.0;
  rig::Validity validity;  //!< see validity.hpp and the header comment
  double simulated_time_s = 0.0;
};

struct LinearityOptions {
  double max_um = 11.0;
  double increment_um = 1.0;
  //! Sweep from max_um down to increment_um (after approaching max_um from below) instead of
  //! upwards. Not to 0: after a descent the stacks' hysteresis leaves them above zero at 0 V,
  //! which the 0..150 V amplifier cannot undo, so Z_d = 0 is out of reach from above.
  bool downward = false;
  double step_hold_s = 10.0;
  std::size_t skip_samples = 2;  //!< static samples left out at the start of each level
  //! A level further than this from Z_d was not reached (5 % of the span: far beyond any
  //! nonlinearity, so only a loop out of authority or a wrong calibration gets there).
  double reach_tolerance_um = 0.5;
  rig::BenchOptions bench{};  //!< feedback (gauges or oracle) and the supervisor's limits
};

struct LinearityResult {
  std::vector<double> desired_um;     //!< per level
  std::vector<double> measured_um;    //!< per level: mean of its samples
  std::vector<double> sample_time_s;  //!< every static sample
  std::vector<double> sample_desired_um;
  std::vector<double> sample_measured_um;
  LinearityMetrics metrics;
  rig::Validity validity;  //!< see validity.hpp and the header comment
  double simulated_time_s = 0.0;
};

struct RepeatabilityOptions {
  double target_um = 5.0;
  int moves = 230;  //!< the paper's count
  double rest_s = 0.5;
  double settle_s = 0.5;
  //! A reading further than this from the target means the move did not reach it.
  double target_tolerance_um = 0.05;
  rig::BenchOptions bench{};  //!< feedback (gauges or oracle) and the supervisor's limits
};

struct RepeatabilityResult {
  double target_um = 0.0;
  std::vector<double> measured_um;  //!< z_i
  RepeatabilityMetrics metrics;
  rig::Validity validity;  //!< see validity.hpp and the header comment
  double simulated_time_s = 0.0;
};

TravelRangeResult run_travel_range(const config::ProjectConfig& config,
                                   const control::SemiClosedLoopParams& controller,
                                   std::uint64_t seed, const TravelRangeOptions& options = {},
                                   const rig::Progress& progress = {});
StepExperimentResult run_step_response(const config::ProjectConfig& config,
                                       const control::SemiClosedLoopParams& controller,
                                       std::uint64_t seed,
                                       const StepExperimentOptions& options = {},
                                       const rig::Progress& progress = {});
LinearityResult run_linearity(const config::ProjectConfig& config,
                              const control::SemiClosedLoopParams& controller, std::uint64_t seed,
                              const LinearityOptions& options = {},
                              const rig::Progress& progress = {});
RepeatabilityResult run_repeatability(const config::ProjectConfig& config,
                                      const control::SemiClosedLoopParams& controller,
                                      std::uint64_t seed, const RepeatabilityOptions& options = {},
                                      const rig::Progress& progress = {});

}  // namespace piezoshift::experiments
