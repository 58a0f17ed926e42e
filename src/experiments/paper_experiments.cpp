#include "piezoshift/experiments/paper_experiments.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include <fmt/core.h>

#include "piezoshift/experiments/bench.hpp"

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

}  // namespace

TravelRangeResult run_travel_range(const io::ProjectConfig& config,
                                   const control::SemiClosedLoopParams& controller,
                                   std::uint64_t seed, const TravelRangeOptions& o,
                                   const Progress& progress) {
  require(o.increment_um > 0.0 && o.max_um > o.start_um && o.hold_s >= 0.0 &&
              o.tolerance_um > 0.0 && o.open_loop_settle_s >= 0.0,
          "travel range: increment > 0, max > start, tolerance > 0");
  TravelRangeResult r;
  {
    Bench open(config, controller, seed);
    open.drive_open_loop(all(10.0));
    open.run(o.open_loop_settle_s);
    r.open_loop_points_um = open.measure_static().points_um;
    r.open_loop_um = mean3(r.open_loop_points_um);
    r.simulated_time_s += open.time_s();
  }
  Bench bench(config, controller, seed + 1);
  const auto levels = static_cast<int>(std::floor((o.max_um - o.start_um) / o.increment_um + 1e-9));
  for (int k = 0; k <= levels; ++k) {
    const double zd = o.start_um + o.increment_um * k;
    bench.drive_points(all(zd));
    bench.run(o.hold_s);
    const double z = mean3(bench.measure_static().points_um);
    const int sat = bench.last_output().saturated_mask;
    r.desired_um.push_back(zd);
    r.measured_um.push_back(z);
    r.saturated_mask.push_back(sat);
    if (progress)
      progress(k + 1, levels + 1, "travel range");
    if (sat != 0 || std::fabs(z - zd) > o.tolerance_um)
      break;
    r.semi_closed_um = zd;
  }
  r.simulated_time_s += bench.time_s();
  return r;
}

StepExperimentResult run_step_response(const io::ProjectConfig& config,
                                       const control::SemiClosedLoopParams& controller,
                                       std::uint64_t seed, const StepExperimentOptions& o,
                                       const Progress& progress) {
  require(o.step_um > 0.0 && o.pre_s > 0.0 && o.record_s > 0.0, "step response: bad options");
  Bench bench(config, controller, seed);
  bench.drive_points(all(0.0));
  bench.run(o.pre_s);
  StepExperimentResult r;
  const double t0 = bench.time_s();
  // The last sample before the step is the response's starting level.
  r.time_s.push_back(0.0);
  r.measured_um.push_back(mean3(bench.twin().interferometer().dynamic_um));
  r.desired_um.push_back(0.0);
  bench.drive_points(all(o.step_um));
  bench.run(o.record_s, [&](const Bench& b) {
    r.time_s.push_back(b.time_s() - t0);
    r.measured_um.push_back(mean3(b.twin().interferometer().dynamic_um));
    r.desired_um.push_back(o.step_um);
  });
  StepResponseOptions m;
  m.step_time_s = 0.0;
  m.band_pct = o.band_pct;
  m.band_nm = o.band_nm;
  r.metrics = step_response_metrics(r.time_s, r.measured_um, m);
  r.simulated_time_s = bench.time_s();
  if (progress)
    progress(1, 1, "step response");
  return r;
}

LinearityResult run_linearity(const io::ProjectConfig& config,
                              const control::SemiClosedLoopParams& controller, std::uint64_t seed,
                              const LinearityOptions& o, const Progress& progress) {
  require(o.max_um > 0.0 && o.increment_um > 0.0 && o.step_hold_s >= 1.0,
          "linearity: max > 0, increment > 0, at least 1 s per level");
  Bench bench(config, controller, seed);
  const int levels = static_cast<int>(std::llround(o.max_um / o.increment_um));
  bench.drive_points(all(0.0));
  bench.run(1.0);
  LinearityResult r;
  for (int k = 0; k <= levels; ++k) {
    const double zd = o.increment_um * k;
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
    if (progress)
      progress(k + 1, levels + 1, "linearity");
  }
  r.metrics = linearity_metrics(r.desired_um, r.measured_um);
  r.simulated_time_s = bench.time_s();
  return r;
}

RepeatabilityResult run_repeatability(const io::ProjectConfig& config,
                                      const control::SemiClosedLoopParams& controller,
                                      std::uint64_t seed, const RepeatabilityOptions& o,
                                      const Progress& progress) {
  require(o.moves >= 2 && o.target_um > 0.0 && o.rest_s >= 0.0 && o.settle_s >= 0.0,
          "repeatability: at least 2 moves and a positive target");
  Bench bench(config, controller, seed);
  RepeatabilityResult r;
  r.target_um = o.target_um;
  const std::string label = fmt::format("repeat. {:g} um", o.target_um);
  for (int i = 0; i < o.moves; ++i) {
    bench.drive_points(all(0.0));
    bench.run(o.rest_s);
    bench.drive_points(all(o.target_um));
    bench.run(o.settle_s);
    r.measured_um.push_back(mean3(bench.measure_static().points_um));
    if (progress)
      progress(i + 1, o.moves, label);
  }
  r.metrics = repeatability_metrics(r.measured_um);
  r.simulated_time_s = bench.time_s();
  return r;
}

}  // namespace piezoshift::experiments
