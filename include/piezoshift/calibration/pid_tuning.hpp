#pragma once
// Calibration stage 1 (paper, Section 3, first step): the PID gains, by the paper's trial and
// error made systematic. For every candidate (kp, ki, kd) on a grid, on a fresh bench (the
// shipping loop, supervisor included: rig/bench.hpp):
//   the three inner loops step together (the stage moves as in use), each SGS target from 0 to
//   its maximum nominal displacement S_max,i, held step_duration_s; scored
//     per actuator, from its SGS feedback y(t) at the ticks (experiments/metrics_step_response.hpp,
//     y_inf = target):
//       overshoot_pct         100 max(0, max y - S) / S
//       settling_time_s       to +- settle_band_pct of the step
//       steady_state_error_nm |mean(y) - S| over the last steady_window_s
//     on the plate, between ticks (the twin's physics-rate truth, mean of P1..P3):
//       plate_overshoot_pct   100 max(0, max z - z_inf) / |z_inf - z_0|
// A candidate is acceptable when its gains are stable on the nominal inner loop (the check every
// calibration file passes at load, runtime/controller_ranges.hpp), the supervisor did not trip,
// every actuator's and the plate's overshoot is <= max_overshoot_pct ("little or even no
// overshoot"), it settled within the record and the steady-state error is <=
// max_steady_state_error_nm. (An actuator stepped alone scores a different loop: the plate couples
// the legs, and the overshoot the single-leg score passed showed on the full step, 3 to 9 %, and
// between the ticks.) Among acceptable candidates the one with the shortest worst settling time
// wins, ties going to the smaller error; if none is acceptable, the smallest worst-case overshoot
// wins and `acceptable` says so.
//
// S_max,i is what actuator i's SGS reads at the full 10 V open loop (measured first, on the
// same twin), times step_fraction (< 1, so that the step scores the loop and not the amplifier's
// rail).
#include <cstdint>
#include <vector>

#include "piezoshift/config/project_config.hpp"
#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/rig/progress.hpp"
#include "piezoshift/runtime/safety_supervisor.hpp"

namespace piezoshift::calibration {

struct PidScore {
  double overshoot_pct = 0.0;
  double settling_time_s = 0.0;  //!< +inf when not settled within the record
  double steady_state_error_nm = 0.0;
};

struct PidTrial {
  control::PidGains gains{};
  std::array<PidScore, 3> per_actuator{};
  PidScore worst{};                  //!< element-wise worst over the three actuators
  double plate_overshoot_pct = 0.0;  //!< the plate between ticks (physics-rate truth)
  bool faulted = false;              //!< the supervisor tripped during the step
  //! On the nominal inner loop (runtime/controller_ranges.hpp): <= 0 dB is a set a calibration file
  //! may not hold, so it is never acceptable.
  double nominal_gain_margin_dB = 0.0;
  bool acceptable = false;
  double simulated_time_s = 0.0;
};

struct PidTuningOptions {
  std::vector<double> kp_values{0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0};
  std::vector<double> ki_values{0.02, 0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5};
  std::vector<double> kd_values{0.0, 0.001, 0.01};
  double step_fraction = 0.95;  //!< of the SGS reading at 10 V open loop
  double step_duration_s = 0.5;
  double settle_band_pct = 2.0;
  double steady_window_s = 0.1;
  double max_overshoot_pct = 1.0;
  double max_steady_state_error_nm = 5.0;
  //! The supervisor's on every bench of the stage (the installation's [safety]; CalibrationOptions
  //! sets it).
  runtime::SafetyLimits limits{};
};

struct PidTuningResult {
  control::Vec3 step_target_um{};  //!< S_max,i per actuator, SGS um
  PidTrial best{};                 //!< the winner (see header)
  PidTrial paper{};                //!< the paper's gains, scored the same way
  std::vector<PidTrial> trials;    //!< every candidate, in grid order (kp outer, kd inner)
  double simulated_time_s = 0.0;   //!< all trials together
};

//! Scores one candidate on a fresh twin built from config and seed. base supplies everything but
//! the gains (sample time, limits, scaling).
PidTrial score_pid_gains(const config::ProjectConfig& config,
                         const control::SemiClosedLoopParams& base, const control::PidGains& gains,
                         const control::Vec3& step_target_um, std::uint64_t seed,
                         const PidTuningOptions& options = {});

//! S_max,i: the SGS readings at 10 V open loop (settled for 1 s), times step_fraction, on a bench
//! supervised with limits.
control::Vec3 maximum_step_targets(const config::ProjectConfig& config,
                                   const control::SemiClosedLoopParams& base, std::uint64_t seed,
                                   double step_fraction, const runtime::SafetyLimits& limits = {});

//! The full grid search; throws std::invalid_argument for an empty grid or a bad option.
PidTuningResult tune_pid(const config::ProjectConfig& config,
                         const control::SemiClosedLoopParams& base, std::uint64_t seed,
                         const PidTuningOptions& options = {}, const rig::Progress& progress = {});

}  // namespace piezoshift::calibration
