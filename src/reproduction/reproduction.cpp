#include "piezoshift/reproduction/reproduction.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <fmt/core.h>
#include <stdexcept>

#include "piezoshift/core/wall_time.hpp"

namespace piezoshift::reproduction {

Schedule Schedule::paper() {
  Schedule s;
  s.repeat_5um.target_um = 5.0;
  s.repeat_10um.target_um = 10.0;
  s.linearity_grid = s.linearity;
  s.linearity_grid.increment_um = 0.25;
  s.linearity_down = s.linearity;
  s.linearity_down.downward = true;
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
  s.linearity_grid.step_hold_s = 2.0;
  s.linearity_grid.skip_samples = 0;
  s.linearity_down.step_hold_s = 4.0;
  s.linearity_down.skip_samples = 1;
  // Repeatability keeps the paper's 230 moves: the twin's spread is dominated by the lab's slow
  // drift over the time the moves take, so fewer moves would measure something else.
  return s;
}

Schedule with_feedback(Schedule s, rig::Feedback f) {
  s.travel.bench.feedback = f;
  s.step.bench.feedback = f;
  s.linearity.bench.feedback = f;
  s.linearity_grid.bench.feedback = f;
  s.linearity_down.bench.feedback = f;
  s.phase_step.bench.feedback = f;
  s.repeat_5um.bench.feedback = f;
  s.repeat_10um.bench.feedback = f;
  return s;
}

Schedule with_limits(Schedule s, const runtime::SafetyLimits& limits) {
  s.calibration.limits = limits;
  for (rig::BenchOptions* b :
       {&s.travel.bench, &s.step.bench, &s.linearity.bench, &s.linearity_grid.bench,
        &s.linearity_down.bench, &s.phase_step.bench, &s.repeat_5um.bench, &s.repeat_10um.bench})
    b->limits = limits;
  return s;
}

ExperimentSet run_experiment_set(const config::ProjectConfig& config,
                                 const control::SemiClosedLoopParams& c, std::uint64_t seed,
                                 const Schedule& s, const rig::Progress& progress) {
  namespace ex = experiments;
  ExperimentSet r;
  r.travel = ex::run_travel_range(config, c, seed + 10, s.travel, progress);
  r.step = ex::run_step_response(config, c, seed + 20, s.step, progress);
  r.linearity = ex::run_linearity(config, c, seed + 30, s.linearity, progress);
  r.repeat_5um = ex::run_repeatability(config, c, seed + 40, s.repeat_5um, progress);
  r.repeat_10um = ex::run_repeatability(config, c, seed + 50, s.repeat_10um, progress);
  r.linearity_grid = ex::run_linearity(config, c, seed + 60, s.linearity_grid, progress);
  r.linearity_down = ex::run_linearity(config, c, seed + 70, s.linearity_down, progress);
  r.phase_step = ex::run_phase_step(config, c, seed + 80, s.phase_step, progress);
  return r;
}

std::vector<double> inner_loop_sample_times_s(const config::ProjectConfig& config) {
  std::vector<double> rates{config.twin.daq.sample_time_s};
  if (config.twin.daq.sample_time_s != kFastSampleTime_s)
    rates.push_back(kFastSampleTime_s);
  return rates;
}

InnerLoopAnalysis analyze_inner_loop_at(const config::ProjectConfig& config,
                                        const control::SemiClosedLoopParams& controller,
                                        double sample_time_s, std::uint64_t seed) {
  config::ProjectConfig at = config;
  control::SemiClosedLoopParams c = controller;
  at.twin.daq.sample_time_s = c.sample_time_s = sample_time_s;
  InnerLoopAnalysis a;
  a.sample_time_s = c.sample_time_s;
  a.pid = c.pid_params();
  try {
    if (c.kind == control::ControllerKind::kImproved) {
      // The plant is identified through the PIDs (they hold the operating point, then the loop
      // is opened); the improved controller's loop is its correction through the model's inverse,
      // judged at the hold's gain and at the boost's ceiling, the worse of the two kept.
      const control::ImprovedParams& im = c.improved;
      if (std::fabs(im.sample_time_s - sample_time_s) > 1e-9 * sample_time_s)
        throw std::invalid_argument(
            fmt::format("the improved controller was calibrated at {} s, not {} s",
                        im.sample_time_s, sample_time_s));
      control::SemiClosedLoopParams through_pids = c;
      through_pids.kind = control::ControllerKind::kPaper;
      a.plant = calibration::identify_loop(at, through_pids, seed);
      a.pid = control::PidParams{};
      a.pid.gains = {0.0, im.correction_ki, 0.0};
      a.margins = calibration::correction_margins(a.plant, im, im.correction_ki);
      const auto boosted = calibration::correction_margins(a.plant, im, im.correction_ki_max);
      for (std::size_t i = 0; i < 3; ++i) {
        a.margins[i].gain_margin_dB =
            std::min(a.margins[i].gain_margin_dB, boosted[i].gain_margin_dB);
        if (boosted[i].phase_margin_deg < a.margins[i].phase_margin_deg) {
          a.margins[i].phase_margin_deg = boosted[i].phase_margin_deg;
          a.margins[i].gain_crossover_Hz = boosted[i].gain_crossover_Hz;
        }
      }
    } else {
      a.plant = calibration::identify_loop(at, c, seed);
      a.margins = calibration::pid_margins(a.plant, a.pid);
    }
  } catch (const std::invalid_argument& e) {  // e.g. a physics rate 10 kHz does not divide
    a.validity.fail(e.what());
  } catch (const rig::ProcedureFailed& e) {
    a.validity.fail(e.what());
  }
  return a;
}

std::vector<InnerLoopAnalysis> analyze_inner_loop(const config::ProjectConfig& config,
                                                  const control::SemiClosedLoopParams& controller,
                                                  std::uint64_t seed,
                                                  const std::string& not_at_10kHz) {
  const std::vector<double> rates = inner_loop_sample_times_s(config);
  std::vector<InnerLoopAnalysis> out;
  for (std::size_t i = 0; i < rates.size(); ++i) {
    if (rates[i] == kFastSampleTime_s && !not_at_10kHz.empty()) {
      InnerLoopAnalysis skipped;
      skipped.sample_time_s = rates[i];
      skipped.validity.fail(not_at_10kHz);
      out.push_back(std::move(skipped));
    } else {
      out.push_back(analyze_inner_loop_at(config, controller, rates[i], seed + 90 + i));
    }
  }
  return out;
}

runtime::StabilityMargins InnerLoopAnalysis::worst() const {
  runtime::StabilityMargins w = margins[0];
  for (const auto& m : margins) {
    w.gain_margin_dB = std::min(w.gain_margin_dB, m.gain_margin_dB);
    if (m.phase_margin_deg < w.phase_margin_deg) {
      w.phase_margin_deg = m.phase_margin_deg;
      w.gain_crossover_Hz = m.gain_crossover_Hz;
    }
  }
  return w;
}

double ExperimentSet::experiments_simulated_time_s() const {
  return travel.simulated_time_s + step.simulated_time_s + linearity.simulated_time_s +
         linearity_grid.simulated_time_s + linearity_down.simulated_time_s +
         repeat_5um.simulated_time_s + repeat_10um.simulated_time_s + phase_step.simulated_time_s;
}

bool ExperimentSet::table4_valid() const {
  return travel.validity.valid && step.validity.valid && linearity.validity.valid &&
         repeat_5um.validity.valid && repeat_10um.validity.valid;
}

std::vector<std::string> ExperimentSet::invalid_reasons() const {
  std::vector<std::string> out;
  const auto add = [&](const char* name, const rig::Validity& v) {
    if (!v.valid)
      out.push_back(std::string(name) + ": " + v.reason);
  };
  add("travel", travel.validity);
  add("step", step.validity);
  add("linearity", linearity.validity);
  add("repeatability 5 um", repeat_5um.validity);
  add("repeatability 10 um", repeat_10um.validity);
  add("linearity (0.25 um grid)", linearity_grid.validity);
  add("linearity (downwards)", linearity_down.validity);
  add("phase step", phase_step.validity);
  return out;
}

std::vector<std::string> ReproductionResult::invalid_reasons() const {
  std::vector<std::string> out = ExperimentSet::invalid_reasons();
  if (!measurement.validity.valid)
    out.push_back("measurement: " + measurement.validity.reason);
  return out;
}

ReproductionResult reproduce(const config::ProjectConfig& config, const ReproduceOptions& options,
                             const rig::Progress& progress) {
  const auto start = std::chrono::steady_clock::now();
  Schedule s = with_limits(options.quick ? Schedule::quick() : Schedule::paper(), options.limits);
  s.calibration.pid = options.pid;
  const std::uint64_t seed = options.seed;
  ReproductionResult r;
  r.options = options;
  r.schedule = s;
  control::SemiClosedLoopParams base{};
  base.sample_time_s = config.twin.daq.sample_time_s;  // the controller runs at the DAQ's rate
  r.calibration = calibration::calibrate(config, base, seed, s.calibration, progress);
  static_cast<ExperimentSet&>(r) =
      run_experiment_set(config, r.calibration.controller, seed, s, progress);
  // Gains and A calibrated, p = identity: the oracle's controller, and the paper's protocol run
  // with it on the gauges shows what p removes.
  r.oracle_controller = r.calibration.controller;
  r.oracle_controller.polynomial = control::CubicPolynomial::identity();
  r.linearity_without_cubic =
      experiments::run_linearity(config, r.oracle_controller, seed + 30, s.linearity, progress);
  r.inner_loop = analyze_inner_loop(config, r.calibration.controller, seed);
  r.measurement = run_phase_measurement(config, r.calibration.controller,
                                        seed + kMeasurementSeedOffset, options.limits);
  // The oracle: the same loop, gains and A, fed the plate's truth; nothing left for p to correct.
  r.oracle = run_experiment_set(config, r.oracle_controller, seed,
                                with_feedback(s, rig::Feedback::kOracle), progress);
  r.simulated_time_s = r.calibration.pid.simulated_time_s + r.calibration.matrix.simulated_time_s +
                       r.calibration.polynomial.simulated_time_s +
                       r.experiments_simulated_time_s() +
                       r.linearity_without_cubic.simulated_time_s +
                       r.oracle.experiments_simulated_time_s() + r.measurement.simulated_time_s;
  r.wall_time_s = core::seconds_since(start);
  return r;
}

}  // namespace piezoshift::reproduction
