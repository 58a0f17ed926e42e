// A diagnostic, not a test: the improved controller calibrated on a plant as compare
// --quick calibrates it at 1 kHz, then compare's 11 um step (run_step_response's seed + 20: 0.5 s
// at 0, then 11 um on the three points) traced per tick: the shaper's output (a local copy of the
// controller's shaper on channel 1's target), the commands, the gauges and the true plate (its
// mean and its extremes between the ticks). Built on demand only:
//   cmake --build --preset release --target large_step_trace
//   build/release/tests/calibration/large_step_trace [default|thick-plate|payload|...]...
// Environment (each optional): DIAG_SEED (1); DIAG_TICKS ticks printed (80); DIAG_RATE_SCALE
// scales the shaper's rate limit; DIAG_NOSHAPE=1 a single tap; DIAG_SHAPER_HZ taps designed at
// this mode; DIAG_TAPS "w0 w1 ..." the taps; DIAG_STEP_UM (11).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "piezoshift/calibration/improved_calibration.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/experiments/paper_experiments.hpp"
#include "piezoshift/reproduction/reproduction.hpp"
#include "piezoshift/rig/bench.hpp"
#include "plant_by_name.hpp"

namespace piezoshift::calibration {
namespace {

double env(const char* name, double fallback) {
  const char* v = std::getenv(name);
  return v ? std::strtod(v, nullptr) : fallback;
}

void trace(const std::string& name, std::uint64_t seed) {
  config::ProjectConfig config = testing::plant_by_name(name);
  ImprovedCalibrationOptions o;
  o.paper = reproduction::Schedule::quick().calibration;
  control::SemiClosedLoopParams base;
  base.sample_time_s = config.twin.daq.sample_time_s;
  ImprovedCalibrationOutcome c = calibrate_improved(config, base, seed, o);
  control::ImprovedParams& im = c.controller.improved;
  im.shaper.rate_um_per_s *= env("DIAG_RATE_SCALE", 1.0);
  im.command_slew_um_per_s = env("DIAG_SLEW", im.command_slew_um_per_s);
  im.slew_approach_um = env("DIAG_APPROACH", im.slew_approach_um);
  if (const char* f = std::getenv("DIAG_SHAPER_HZ"))  // taps designed at this mode instead
    im.shaper = control::design_mode_shaper(std::strtod(f, nullptr), c.controller.sample_time_s,
                                            im.shaper.rate_um_per_s);
  if (const char* taps = std::getenv("DIAG_TAPS")) {  // "w0 w1 ..." (spaced by blanks)
    im.shaper.taps = 0;
    im.shaper.weight = {};
    char* end = nullptr;
    for (const char* q = taps; im.shaper.taps < control::kMaxShaperTaps; q = end) {
      const double w = std::strtod(q, &end);
      if (end == q)
        break;
      im.shaper.weight[im.shaper.taps++] = w;
    }
  }
  if (std::getenv("DIAG_NOSHAPE")) {
    im.shaper.taps = 1;
    im.shaper.weight = {};
    im.shaper.weight[0] = 1.0;
  }
  std::printf("== %s seed %llu: mode %.1f Hz (r %.3f) shaped %d taps %zu [", name.c_str(),
              static_cast<unsigned long long>(seed), c.mode.mode_Hz, c.mode.pole_radius,
              c.shaped ? 1 : 0, im.shaper.taps);
  for (std::size_t i = 0; i < im.shaper.taps; ++i)
    std::printf(" %.3f", im.shaper.weight[i]);
  std::printf(" ] rate %.0f um/s slew %.0f um/s D %zu out %.2f..%.2f um\n", im.shaper.rate_um_per_s,
              im.command_slew_um_per_s, im.reference_delay_ticks, c.controller.output_min_um,
              c.controller.output_max_um);
  {  // compare's figures, exactly (run_step_response on seed + 20, the quick schedule's options)
    experiments::StepExperimentOptions so = reproduction::Schedule::quick().step;
    so.step_um = env("DIAG_STEP_UM", so.step_um);
    const experiments::StepExperimentResult s =
        experiments::run_step_response(config, c.controller, seed + 20, so);
    std::printf(
        "  compare: valid %d settle +-10 nm %.1f ms, +-2 %% %.1f ms, true overshoot %.2f %%\n",
        s.validity.valid ? 1 : 0, 1e3 * s.metrics.settling_time_abs_s,
        1e3 * s.metrics.settling_time_pct_s, s.truth_overshoot_pct);
    for (std::size_t k = 0; k < s.time_s.size() && std::getenv("DIAG_IFM"); ++k)
      if (s.time_s[k] < 0.08)
        std::printf("  ifm t %.1f ms %.4f um\n", 1e3 * s.time_s[k], s.measured_um[k]);
  }
  const double step_um = env("DIAG_STEP_UM", 11.0);
  const auto ticks = static_cast<int>(env("DIAG_TICKS", 80));
  rig::Bench bench(config, c.controller, seed + 20);
  bench.drive_points(control::Vec3{0.0, 0.0, 0.0});
  bench.run(0.5);
  const double t0 = bench.time_s();
  const auto mean3 = [](const control::Vec3& v) { return (v[0] + v[1] + v[2]) / 3.0; };
  const double z0 = mean3(bench.twin().truth().points_um);
  control::SetpointShaper shaper;
  shaper.configure(im.shaper, c.controller.sample_time_s);
  shaper.reset(bench.last_output().target_um[0]);
  std::vector<double> truth;
  double peak = z0;
  int k = 0;
  bench.drive_points(control::Vec3{step_um, step_um, step_um});
  bench.run(1.0, [&](const rig::Bench& b) {
    const plant::TwinTruth& t = b.twin().truth();
    const control::ControllerOutput& out = b.last_output();
    const double r = shaper.update(out.target_um[0]);
    truth.push_back(mean3(t.points_um));
    peak = std::max(peak, t.period_max_mean_points_um);
    if (k++ < ticks || (k % 50 == 0))
      std::printf(
          "t %6.1f ms S1 %6.3f r1 %6.3f u %6.3f %6.3f %6.3f amp %6.1f %6.1f %6.1f gauge %6.3f "
          "truth %7.4f [%7.4f %7.4f] sat %d\n",
          1e3 * (b.time_s() - t0), out.target_um[0], r, out.command_um[0], out.command_um[1],
          out.command_um[2], t.amplifier_V[0], t.amplifier_V[1], t.amplifier_V[2],
          mean3(out.feedback_um), mean3(t.points_um) - z0, t.period_min_mean_points_um - z0,
          t.period_max_mean_points_um - z0, out.saturated_mask);
  });
  const std::size_t tail = std::max<std::size_t>(1, truth.size() / 10);
  double fin = 0.0;
  for (std::size_t j = truth.size() - tail; j < truth.size(); ++j)
    fin += truth[j] / static_cast<double>(tail);
  std::size_t peak_k = 0;
  for (std::size_t j = 0; j < truth.size(); ++j)
    if (truth[j] > truth[peak_k])
      peak_k = j;
  std::printf("  truth final %.4f um, peak %.4f um (tick peak %.4f at %zu ms): overshoot %.2f %%\n",
              fin - z0, peak - z0, truth[peak_k] - z0, peak_k + 1,
              100.0 * (peak - fin) / std::fabs(fin - z0));
}

}  // namespace
}  // namespace piezoshift::calibration

int main(int argc, char** argv) {
  const std::uint64_t seed =
      static_cast<std::uint64_t>(piezoshift::calibration::env("DIAG_SEED", 1));
  std::vector<std::string> names(argv + 1, argv + argc);
  if (names.empty())
    names = {"default", "payload", "contact-spread", "thick-plate"};
  for (const std::string& n : names)
    piezoshift::calibration::trace(n, seed);
  return 0;
}
