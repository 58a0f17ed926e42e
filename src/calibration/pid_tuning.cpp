#include "piezoshift/calibration/pid_tuning.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "piezoshift/experiments/metrics_step_response.hpp"
#include "piezoshift/rig/bench.hpp"
#include "piezoshift/runtime/controller_ranges.hpp"

namespace piezoshift::calibration {
namespace {

using control::Vec3;

PidScore score_trace(const std::vector<double>& t, const std::vector<double>& y, double t_step,
                     double target, const PidTuningOptions& o) {
  experiments::StepResponseOptions so;
  so.step_time_s = t_step;
  so.final_um = target;
  so.band_pct = o.settle_band_pct;
  const auto m = experiments::step_response_metrics(t, y, so);
  PidScore s;
  s.overshoot_pct = m.overshoot_pct;
  s.settling_time_s = m.settling_time_pct_s;
  const double window_start = t.back() - o.steady_window_s;
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t k = 0; k < t.size(); ++k) {
    if (t[k] > window_start) {
      sum += y[k];
      ++n;
    }
  }
  s.steady_state_error_nm = std::fabs(sum / static_cast<double>(n) - target) * 1000.0;
  return s;
}

bool better(const PidTrial& a, const PidTrial& b) {
  if (a.acceptable != b.acceptable)
    return a.acceptable;
  if (!a.acceptable)
    return a.worst.overshoot_pct < b.worst.overshoot_pct;
  if (a.worst.settling_time_s != b.worst.settling_time_s) {
    return a.worst.settling_time_s < b.worst.settling_time_s;
  }
  return a.worst.steady_state_error_nm < b.worst.steady_state_error_nm;
}

}  // namespace

Vec3 maximum_step_targets(const config::ProjectConfig& config,
                          const control::SemiClosedLoopParams& base, std::uint64_t seed,
                          double step_fraction, const runtime::SafetyLimits& limits) {
  if (!(step_fraction > 0.0 && step_fraction < 1.0)) {
    throw std::invalid_argument("PID tuning: step_fraction must be in (0, 1)");
  }
  rig::Bench bench(config, base, seed, {rig::Feedback::kGauges, limits});
  bench.drive_open_loop(Vec3{10.0, 10.0, 10.0});
  bench.run(1.0);
  Vec3 sum{};
  const int n = 100;
  for (int k = 0; k < n; ++k) {
    bench.run(bench.sample_time_s());
    for (std::size_t i = 0; i < 3; ++i)
      sum[i] += bench.last_output().feedback_um[i];
  }
  Vec3 target{};
  for (std::size_t i = 0; i < 3; ++i)
    target[i] = step_fraction * sum[i] / n;
  return target;
}

PidTrial score_pid_gains(const config::ProjectConfig& config,
                         const control::SemiClosedLoopParams& base, const control::PidGains& gains,
                         const Vec3& step_target_um, std::uint64_t seed,
                         const PidTuningOptions& options) {
  control::SemiClosedLoopParams params = base;
  params.gains = gains;
  params.gains_sample_time_s = base.sample_time_s;
  rig::Bench bench(config, params, seed, {rig::Feedback::kGauges, options.limits});
  PidTrial trial;
  trial.gains = gains;
  const double rest_s = 0.2;
  bench.drive_actuators(Vec3{});
  bench.run(rest_s);
  // All three legs step together, as the stage moves in use; one sample before the step sets y0.
  std::array<std::vector<double>, 3> y;
  std::vector<double> t{bench.time_s()}, plate{};
  for (std::size_t i = 0; i < 3; ++i)
    y[i].push_back(bench.last_output().feedback_um[i]);
  const auto& truth = bench.twin().truth();
  const double plate_0 = (truth.points_um[0] + truth.points_um[1] + truth.points_um[2]) / 3.0;
  double plate_max = plate_0;
  const double t_step = bench.time_s();
  bench.drive_actuators(step_target_um);
  bench.run(options.step_duration_s, [&](const rig::Bench& b) {
    t.push_back(b.time_s());
    for (std::size_t i = 0; i < 3; ++i)
      y[i].push_back(b.last_output().feedback_um[i]);
    const auto& tr = b.twin().truth();
    plate.push_back((tr.points_um[0] + tr.points_um[1] + tr.points_um[2]) / 3.0);
    plate_max = std::max(plate_max, tr.period_max_mean_points_um);
  });
  for (std::size_t i = 0; i < 3; ++i)
    trial.per_actuator[i] = score_trace(t, y[i], t_step, step_target_um[i], options);
  // The plate between ticks, against its own final value (mean over the steady window).
  const auto window = static_cast<std::size_t>(
      std::max(1.0, std::round(options.steady_window_s / bench.sample_time_s())));
  double plate_final = 0.0;
  for (std::size_t k = plate.size() - std::min(window, plate.size()); k < plate.size(); ++k)
    plate_final += plate[k];
  plate_final /= static_cast<double>(std::min(window, plate.size()));
  trial.plate_overshoot_pct =
      std::max(0.0, 100.0 * (plate_max - plate_final) / std::fabs(plate_final - plate_0));
  PidScore& w = trial.worst;
  for (const PidScore& s : trial.per_actuator) {
    w.overshoot_pct = std::max(w.overshoot_pct, s.overshoot_pct);
    w.settling_time_s = std::max(w.settling_time_s, s.settling_time_s);
    w.steady_state_error_nm = std::max(w.steady_state_error_nm, s.steady_state_error_nm);
  }
  trial.faulted = bench.faulted();
  trial.simulated_time_s = bench.time_s();
  trial.nominal_gain_margin_dB = runtime::nominal_gain_margin_dB(params);
  trial.acceptable = trial.nominal_gain_margin_dB > 0.0 && !trial.faulted &&
                     w.overshoot_pct <= options.max_overshoot_pct &&
                     trial.plate_overshoot_pct <= options.max_overshoot_pct &&
                     std::isfinite(w.settling_time_s) &&
                     w.steady_state_error_nm <= options.max_steady_state_error_nm;
  return trial;
}

PidTuningResult tune_pid(const config::ProjectConfig& config,
                         const control::SemiClosedLoopParams& base, std::uint64_t seed,
                         const PidTuningOptions& options, const rig::Progress& progress) {
  if (options.kp_values.empty() || options.ki_values.empty() || options.kd_values.empty()) {
    throw std::invalid_argument("PID tuning: every gain needs at least one candidate value");
  }
  PidTuningResult r;
  r.step_target_um =
      maximum_step_targets(config, base, seed, options.step_fraction, options.limits);
  const double total = static_cast<double>(options.kp_values.size() * options.ki_values.size() *
                                           options.kd_values.size()) +
                       1.0;
  double done = 0.0;
  // The paper's gains are per sample at 1 ms; the grid's are per sample at the bench's own rate.
  const control::PidGains paper_gains =
      control::rescale_gains(control::PidGains{}, 1e-3, base.sample_time_s);
  r.paper = score_pid_gains(config, base, paper_gains, r.step_target_um, seed, options);
  r.simulated_time_s += r.paper.simulated_time_s + 1.1;  // + the 10 V open-loop reading
  if (progress)
    progress(++done, total, "PID gains");
  bool first = true;
  for (double kp : options.kp_values) {
    for (double ki : options.ki_values) {
      for (double kd : options.kd_values) {
        r.trials.push_back(score_pid_gains(config, base, control::PidGains{kp, ki, kd},
                                           r.step_target_um, seed, options));
        r.simulated_time_s += r.trials.back().simulated_time_s;
        if (first || better(r.trials.back(), r.best))
          r.best = r.trials.back();
        first = false;
        if (progress)
          progress(++done, total, "PID gains");
      }
    }
  }
  return r;
}

}  // namespace piezoshift::calibration
