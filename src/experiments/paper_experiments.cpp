#include "piezoshift/experiments/paper_experiments.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <fmt/core.h>

#include "bench_checks.hpp"

namespace piezoshift::experiments {
namespace {

using control::Vec3;

double mean3(const Vec3& v) {
  return (v[0] + v[1] + v[2]) / 3.0;
}
Vec3 all(double v) {
  return Vec3{v, v, v};
}

void require(bool ok, const char* what) {
  if (!ok)
    throw std::invalid_argument(what);
}

using detail::check_fault;
using detail::saturation_problem;

}  // namespace

TravelRangeResult run_travel_range(const config::ProjectConfig& config,
                                   const control::SemiClosedLoopParams& controller,
                                   std::uint64_t seed, const TravelRangeOptions& o,
                                   const rig::Progress& progress) {
  require(o.increment_um > 0.0 && o.max_um > o.start_um && o.hold_s >= 0.0 &&
              o.tolerance_um > 0.0 && o.open_loop_settle_s >= 0.0,
          "travel range: increment > 0, max > start, tolerance > 0");
  TravelRangeResult r;
  {
    rig::Bench open(config, controller, seed, o.bench);
    open.drive_open_loop(all(10.0));
    open.run(o.open_loop_settle_s);
    r.open_loop_points_um = open.measure_static().points_um;
    r.open_loop_um = mean3(r.open_loop_points_um);
    r.simulated_time_s += open.time_s();
    check_fault(open, r.validity, "during the open-loop reading");
  }
  // The search starts at start_um; a stage that cannot track even that is searched again from
  // one coarse_step_um lower, so a short stage gets its real travel, not a 0.
  double start = o.start_um;
  bool ended_tracking = false;
  double searched_s = 0.0;
  for (int attempt = 0; start > 0.0 && r.semi_closed_um == 0.0; ++attempt) {
    if (attempt > 0)
      start -= o.coarse_step_um;
    if (start <= 0.0)
      break;
    rig::Bench bench(config, controller, seed + 1, o.bench);
    const auto levels = static_cast<int>(std::floor((o.max_um - start) / o.increment_um + 1e-9));
    for (int k = 0; k <= levels; ++k) {
      const double zd = start + o.increment_um * k;
      bench.drive_points(all(zd));
      bench.run(o.hold_s);
      const double z = mean3(bench.measure_static().points_um);
      const int sat = bench.last_output().saturated_mask;
      r.desired_um.push_back(zd);
      r.measured_um.push_back(z);
      r.saturated_mask.push_back(sat);
      if (progress)
        progress(k + 1, levels + 1, "travel range");
      // The first level not tracked (the loop out of authority, the supervisor tripped by it, or
      // the plate too far from Z_d) ends the search: that is the travel's end, not a failure.
      if (sat != 0 || bench.faulted() || std::fabs(z - zd) > o.tolerance_um)
        break;
      r.semi_closed_um = zd;
      r.tracked_levels.push_back(zd);
      ended_tracking = k == levels;
    }
    searched_s += bench.time_s();
  }
  if (ended_tracking)
    r.validity.fail(fmt::format("still tracking at the search's end, {:g} um", o.max_um));
  if (r.semi_closed_um == 0.0)
    r.validity.fail(fmt::format("no level from {:g} um down to {:g} um was tracked", o.start_um,
                                o.coarse_step_um));
  r.simulated_time_s += searched_s;
  // The travel one move reaches from rest: creeping up lets the stacks' creep lower the drive a
  // level needs, which a single move does not wait for.
  for (std::size_t k = r.validity.valid ? r.tracked_levels.size() : 0; k-- > 0;) {
    const double z = r.tracked_levels[k];
    rig::Bench single(config, controller, seed + 2, o.bench);
    single.drive_points(all(0.0));
    single.run(0.2);
    single.drive_points(all(z));
    single.run(o.hold_s);
    const double measured = mean3(single.measure_static().points_um);
    r.simulated_time_s += single.time_s();
    if (!single.faulted() && single.last_output().saturated_mask == 0 &&
        std::fabs(measured - z) <= o.tolerance_um) {
      r.single_move_um = z;
      break;
    }
  }
  if (r.validity.valid && r.single_move_um == 0.0)
    r.validity.fail(
        fmt::format("no level from {:g} um up was reached by a single move from rest", o.start_um));
  // The lowest level one move from the top reaches: after a descent the stacks' hysteresis
  // leaves them above zero at 0 V, which the 0..150 V amplifier cannot undo.
  for (int k = 0; r.single_move_um > 0.0 && k * o.min_increment_um < r.single_move_um; ++k) {
    const double z = k * o.min_increment_um;
    rig::Bench down(config, controller, seed + 3, o.bench);
    down.drive_points(all(r.single_move_um));
    down.run(o.hold_s);
    down.drive_points(all(z));
    down.run(o.hold_s);
    const double measured = mean3(down.measure_static().points_um);
    r.simulated_time_s += down.time_s();
    // In authority (no PID at 0 V, where only the stacks' creep would bring the plate down).
    if (!down.faulted() && down.last_output().saturated_mask == 0 &&
        std::fabs(measured - z) <= o.tolerance_um) {
      r.single_move_min_um = z;
      break;
    }
  }
  return r;
}

StepExperimentResult run_step_response(const config::ProjectConfig& config,
                                       const control::SemiClosedLoopParams& controller,
                                       std::uint64_t seed, const StepExperimentOptions& o,
                                       const rig::Progress& progress) {
  require(o.step_um > 0.0 && o.pre_s > 0.0 && o.record_s > 0.0, "step response: bad options");
  rig::Bench bench(config, controller, seed, o.bench);
  bench.drive_points(all(0.0));
  bench.run(o.pre_s);
  StepExperimentResult r;
  const double t0 = bench.time_s();
  // The last sample before the step is the response's starting level.
  r.time_s.push_back(0.0);
  r.measured_um.push_back(mean3(bench.twin().interferometer().dynamic_um));
  r.desired_um.push_back(0.0);
  r.truth_um.push_back(mean3(bench.twin().truth().points_um));
  double truth_peak = r.truth_um.front();
  bench.drive_points(all(o.step_um));
  bench.run(o.record_s, [&](const rig::Bench& b) {
    r.time_s.push_back(b.time_s() - t0);
    r.measured_um.push_back(mean3(b.twin().interferometer().dynamic_um));
    r.desired_um.push_back(o.step_um);
    r.truth_um.push_back(mean3(b.twin().truth().points_um));
    truth_peak = std::max(truth_peak, b.twin().truth().period_max_mean_points_um);
  });
  // The plate between the ticks: its peak over every physics step against its final value (the
  // mean of the last tenth of the record, as the interferometer's metrics take it).
  const std::size_t tail = std::max<std::size_t>(1, r.truth_um.size() / 10);
  double truth_final = 0.0;
  for (std::size_t k = r.truth_um.size() - tail; k < r.truth_um.size(); ++k)
    truth_final += r.truth_um[k] / static_cast<double>(tail);
  r.truth_overshoot_pct =
      std::max(0.0, 100.0 * (truth_peak - truth_final) / std::fabs(truth_final - r.truth_um[0]));
  StepResponseOptions m;
  m.step_time_s = 0.0;
  m.band_pct = o.band_pct;
  m.band_nm = o.band_nm;
  try {
    r.metrics = step_response_metrics(r.time_s, r.measured_um, m);
  } catch (const MetricsError& e) {
    r.validity.fail(fmt::format("the step response has no metrics: {}", e.what()));
    r.metrics.settling_time_pct_s = r.metrics.settling_time_abs_s =
        std::numeric_limits<double>::infinity();
  }
  r.simulated_time_s = bench.time_s();
  check_fault(bench, r.validity, "during the step");
  if (const std::string sat = saturation_problem(bench, o.step_um); !sat.empty())
    r.validity.fail(sat + " at the end of the record");
  if (!std::isfinite(r.metrics.settling_time_pct_s))
    r.validity.fail(
        fmt::format("the step never settled within +-{:g} % in {:g} s", o.band_pct, o.record_s));
  if (std::fabs(r.metrics.final_um - o.step_um) > o.target_tolerance_um)
    r.validity.fail(
        fmt::format("the step did not reach its target: {:.3f} um for {:g} um "
                    "(tolerance {:g} um)",
                    r.metrics.final_um, o.step_um, o.target_tolerance_um));
  if (progress)
    progress(1, 1, "step response");
  return r;
}

LinearityResult run_linearity(const config::ProjectConfig& config,
                              const control::SemiClosedLoopParams& controller, std::uint64_t seed,
                              const LinearityOptions& o, const rig::Progress& progress) {
  require(o.max_um > 0.0 && o.increment_um > 0.0 && o.step_hold_s >= 1.0,
          "linearity: max > 0, increment > 0, at least 1 s per level");
  rig::Bench bench(config, controller, seed, o.bench);
  const int levels = static_cast<int>(std::llround(o.max_um / o.increment_um));
  if (o.downward) {  // approach the top from below, as the upward sweep does
    bench.drive_points(all(0.0));
    bench.run(1.0);
  }
  bench.drive_points(all(o.downward ? o.increment_um * levels : 0.0));
  bench.run(1.0);
  LinearityResult r;
  // Downwards the sweep ends one increment above 0: after a descent the stacks' hysteresis leaves
  // them above zero at 0 V, and the 0..150 V amplifier cannot pull them back.
  const int last = o.downward ? levels - 1 : levels;
  for (int k = 0; k <= last; ++k) {
    const double zd = o.increment_um * (o.downward ? levels - k : k);
    bench.drive_points(all(zd));
    const double end = bench.time_s() + o.step_hold_s;
    std::uint64_t seen = bench.twin().interferometer().static_count;
    double sum = 0.0;
    std::size_t n = 0, index = 0;
    while (bench.time_s() < end - 0.5 * bench.sample_time_s()) {
      bench.run(bench.sample_time_s());
      const auto& ifm = bench.twin().interferometer();
      if (ifm.static_count != seen) {
        seen = ifm.static_count;
        const double z = mean3(ifm.static_um);
        r.sample_time_s.push_back(ifm.static_time_s);
        r.sample_desired_um.push_back(zd);
        r.sample_measured_um.push_back(z);
        if (index++ >= o.skip_samples) {
          sum += z;
          ++n;
        }
      }
    }
    require(n > 0, "linearity: no sample left after skip_samples; hold longer");
    r.desired_um.push_back(zd);
    r.measured_um.push_back(sum / static_cast<double>(n));
    if (const std::string sat = saturation_problem(bench, zd); !sat.empty())
      r.validity.fail(sat);
    if (std::fabs(r.measured_um.back() - zd) > o.reach_tolerance_um)
      r.validity.fail(fmt::format("Z_d = {:g} um was not reached: {:.3f} um (tolerance {:g} um)",
                                  zd, r.measured_um.back(), o.reach_tolerance_um));
    if (progress)
      progress(k + 1, last + 1, "linearity");
  }
  try {
    r.metrics = linearity_metrics(r.desired_um, r.measured_um);
  } catch (const MetricsError& e) {
    r.validity.fail(fmt::format("the sweep has no linearity: {}", e.what()));
  }
  r.simulated_time_s = bench.time_s();
  check_fault(bench, r.validity, "during the linearity run");
  return r;
}

RepeatabilityResult run_repeatability(const config::ProjectConfig& config,
                                      const control::SemiClosedLoopParams& controller,
                                      std::uint64_t seed, const RepeatabilityOptions& o,
                                      const rig::Progress& progress) {
  require(o.moves >= 2 && o.target_um > 0.0 && o.rest_s >= 0.0 && o.settle_s >= 0.0,
          "repeatability: at least 2 moves and a positive target");
  rig::Bench bench(config, controller, seed, o.bench);
  RepeatabilityResult r;
  r.target_um = o.target_um;
  const std::string label = fmt::format("repeat. {:g} um", o.target_um);
  for (int i = 0; i < o.moves; ++i) {
    bench.drive_points(all(0.0));
    bench.run(o.rest_s);
    bench.drive_points(all(o.target_um));
    bench.run(o.settle_s);
    r.measured_um.push_back(mean3(bench.measure_static().points_um));
    if (const std::string sat = saturation_problem(bench, o.target_um); !sat.empty())
      r.validity.fail(fmt::format("move {}: {}", i + 1, sat));
    if (std::fabs(r.measured_um.back() - o.target_um) > o.target_tolerance_um)
      r.validity.fail(
          fmt::format("move {} did not reach its target: {:.3f} um for {:g} um "
                      "(tolerance {:g} um)",
                      i + 1, r.measured_um.back(), o.target_um, o.target_tolerance_um));
    if (progress)
      progress(i + 1, o.moves, label);
  }
  try {
    r.metrics = repeatability_metrics(r.measured_um);
  } catch (const MetricsError& e) {
    r.validity.fail(fmt::format("the moves have no repeatability: {}", e.what()));
  }
  r.simulated_time_s = bench.time_s();
  check_fault(bench, r.validity, "during the repeatability run");
  return r;
}

}  // namespace piezoshift::experiments
