#include "piezoshift/reproduction/reproduction.hpp"

#include <chrono>

namespace piezoshift::reproduction {

Schedule Schedule::paper() {
  Schedule s;
  s.repeat_5um.target_um = 5.0;
  s.repeat_10um.target_um = 10.0;
  return s;
}

Schedule Schedule::quick() {
  Schedule s = paper();
  auto& pid = s.calibration.pid_tuning;
  pid.kp_values = {0.3, 0.6, 0.9};
  pid.ki_values = {0.1, 0.2, 0.4};
  pid.kd_values = {0.001};
  pid.step_duration_s = 0.3;
  s.calibration.matrix.repeats = 1;
  s.calibration.polynomial.settle_s = 0.5;
  s.travel.open_loop_settle_s = 2.0;
  s.travel.start_um = 11.0;
  s.travel.hold_s = 0.5;
  s.linearity.step_hold_s = 4.0;
  s.linearity.skip_samples = 1;
  // Repeatability keeps the paper's 230 moves: the twin's spread is dominated by the lab's slow
  // drift over the time the moves take, so fewer moves would measure something else.
  return s;
}

ReproductionResult reproduce(const io::ProjectConfig& config, const ReproduceOptions& options,
                             const experiments::Progress& progress) {
  const auto start = std::chrono::steady_clock::now();
  Schedule s = options.quick ? Schedule::quick() : Schedule::paper();
  s.calibration.pid = options.pid;
  const std::uint64_t seed = options.seed;
  ReproductionResult r;
  r.options = options;
  r.schedule = s;
  control::SemiClosedLoopParams base{};
  base.sample_time_s = config.twin.daq.sample_time_s;  // the controller runs at the DAQ's rate
  r.calibration = calibration::calibrate(config, base, seed, s.calibration, progress);
  const auto& c = r.calibration.controller;
  r.travel = experiments::run_travel_range(config, c, seed + 10, s.travel, progress);
  r.step = experiments::run_step_response(config, c, seed + 20, s.step, progress);
  r.linearity = experiments::run_linearity(config, c, seed + 30, s.linearity, progress);
  r.repeat_5um = experiments::run_repeatability(config, c, seed + 40, s.repeat_5um, progress);
  r.repeat_10um = experiments::run_repeatability(config, c, seed + 50, s.repeat_10um, progress);
  r.simulated_time_s = r.calibration.pid.simulated_time_s + r.calibration.matrix.simulated_time_s +
                       r.calibration.polynomial.simulated_time_s + r.travel.simulated_time_s +
                       r.step.simulated_time_s + r.linearity.simulated_time_s +
                       r.repeat_5um.simulated_time_s + r.repeat_10um.simulated_time_s;
  r.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

}  // namespace piezoshift::reproduction
