// A diagnostic, not a test: the improved controller calibrated on a plant as compare
// --quick calibrates it at 1 kHz, its lambda/8 step (compare's seed + 80) and the 1 ms exposure
// means of the true plate, minus the same seed's record without the step (own err). Built on
// demand only: cmake --build --preset release --target improved_step_trace, then
//   build/release/tests/calibration/improved_step_trace [default|thick-plate|payload|...]...
// Environment (each optional): DIAG_SEED (1); DIAG_TAPS "w0 w1 ..." replaces the shaper's taps;
// DIAG_SHORT=1 the shortest positive three-tap shaper on the identified mode (taps 0, n-1, n);
// DIAG_DAMPING the twin's modal damping ratio; DIAG_MODE_S stage 5's record length; DIAG_NOBOOST=1
// no correction boost; DIAG_KI_SCALE scales the correction's gain; DIAG_TRUE=1 also prints the
// true plate per tick (its mean, min and max over the tick) for 30 ms after the same step;
// DIAG_MODE_OUT=FILE writes stage 5's record.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <string>
#include <vector>

#include "piezoshift/calibration/improved_calibration.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/experiments/phase_step.hpp"
#include "piezoshift/reproduction/reproduction.hpp"
#include "piezoshift/rig/bench.hpp"
#include "plant_by_name.hpp"

namespace piezoshift::calibration {
namespace {

void trace(const std::string& name, std::uint64_t seed) {
  {
    config::ProjectConfig config = testing::plant_by_name(name);
    if (const char* d = std::getenv("DIAG_DAMPING"))
      config.twin.mechanics.modal_damping_ratio = std::strtod(d, nullptr);
    if (const char* r = std::getenv("DIAG_IFM_HZ"))
      config.twin.interferometer.dynamic_sample_rate_Hz = std::strtod(r, nullptr);
    ImprovedCalibrationOptions o;
    if (const char* m = std::getenv("DIAG_MODE_S"))
      o.mode_record_s = std::strtod(m, nullptr);
    o.paper = reproduction::Schedule::quick().calibration;
    control::SemiClosedLoopParams base;
    base.sample_time_s = config.twin.daq.sample_time_s;
    ImprovedCalibrationOutcome c = calibrate_improved(config, base, seed, o);
    if (const char* taps = std::getenv("DIAG_TAPS")) {  // "w0 w1 ..." (spaced by blanks)
      control::ShaperParams& sp = c.controller.improved.shaper;
      sp.taps = 0;
      sp.weight = {};
      char* end = nullptr;
      for (const char* q = taps; sp.taps < control::kMaxShaperTaps; q = end) {
        const double w = std::strtod(q, &end);
        if (end == q)
          break;
        sp.weight[sp.taps++] = w;
      }
    }
    if (const char* f = std::getenv("DIAG_MODE_OUT")) {
      std::FILE* out = std::fopen(f, "w");
      for (std::size_t k = 0; k < c.mode_record_um.size(); ++k)
        std::fprintf(out, "%.9g %.9g\n", c.mode_record_t_s[k], c.mode_record_um[k]);
      std::fclose(out);
    }
    if (std::getenv("DIAG_NOBOOST"))
      c.controller.improved.correction_ki_max = c.controller.improved.correction_ki;
    if (const char* k = std::getenv("DIAG_KI_SCALE"))
      c.controller.improved.correction_ki *= std::strtod(k, nullptr);
    if (std::getenv("DIAG_SHORT") && c.shaped) {
      const double two_pi = 2.0 * std::numbers::pi;
      double th = std::fmod(two_pi * c.mode.mode_Hz * 1e-3, two_pi);
      if (th > std::numbers::pi)
        th = two_pi - th;
      const auto n =
          static_cast<std::size_t>(std::max(2.0, std::ceil(std::numbers::pi / th - 1e-12)));
      const double a = static_cast<double>(n - 1) * th, b = static_cast<double>(n) * th;
      const double w0 = std::sin(th), w1 = -std::sin(b), w2 = std::sin(a), sum = w0 + w1 + w2;
      control::ShaperParams& sp = c.controller.improved.shaper;
      sp.weight = {};
      sp.taps = n + 1;
      sp.weight[0] = w0 / sum;
      sp.weight[n - 1] += w1 / sum;
      sp.weight[n] += w2 / sum;
    }
    const control::ImprovedParams& im = c.controller.improved;
    std::printf("== %s seed %llu: holding %.2f mode %.1f Hz (r %.3f) shaped %d taps %zu [",
                name.c_str(), static_cast<unsigned long long>(seed), c.holding.scale,
                c.mode.mode_Hz, c.mode.pole_radius, c.shaped ? 1 : 0, im.shaper.taps);
    for (std::size_t i = 0; i < im.shaper.taps; ++i)
      std::printf(" %.3f", im.shaper.weight[i]);
    std::printf(" ] rate %.0f um/s D %zu\n", im.shaper.rate_um_per_s, im.reference_delay_ticks);
    for (std::size_t i = 0; i < 3; ++i)
      std::printf("  ch%zu: rms %.2f nm delay %zu w0 %.4f g %.4f\n", i + 1,
                  1e3 * c.model[i].rms_residual_um, c.model[i].delay_ticks,
                  c.model[i].params.linear_weight, c.model[i].params.creep_gain);
    if (std::getenv("DIAG_TRUE")) {
      rig::Bench b(config, c.controller, seed + 80);
      b.drive_points(control::Vec3{5.0, 5.0, 5.0});
      b.run(1.5);
      const double z0 = b.twin().truth().period_avg_mean_points_um;
      b.drive_points(control::Vec3{5.0791, 5.0791, 5.0791});
      b.run(0.03, [&](const rig::Bench& x) {
        const plant::TwinTruth& t = x.twin().truth();
        std::printf("  sgs1 %.2f ",
                    1e3 * c.controller.scaling[0].sgs_to_um(x.last_cycle().ai_V[0]));
        std::printf("  tick %.1f ms avg %.2f min %.2f max %.2f u %.4f\n", 1e3 * (t.time_s - 1.5),
                    1e3 * (t.period_avg_mean_points_um - z0),
                    1e3 * (t.period_min_mean_points_um - z0),
                    1e3 * (t.period_max_mean_points_um - z0), t.ao_V[0]);
      });
    }
    const experiments::PhaseStepOptions po = reproduction::Schedule::quick().phase_step;
    const experiments::PhaseStepResult p =
        experiments::run_phase_step(config, c.controller, seed + 80, po);
    std::printf("  valid %d settle %.1f ms own %.1f ms jitter %.3f final %.2f nm wander %.2f\n",
                p.validity.valid ? 1 : 0, 1e3 * p.settling_time_s, 1e3 * p.own_settling_time_s,
                p.hold_jitter_nm_rms, p.final_error_nm, p.still_wander_nm);
    for (std::size_t k = 0; k < p.time_s.size() && p.time_s[k] < 0.06; ++k)
      std::printf("  t %.1f ms: %.2f (still %.2f) own err %.2f\n", 1e3 * p.time_s[k],
                  p.exposure_mean_nm[k], p.still_exposure_mean_nm[k],
                  p.exposure_mean_nm[k] - p.still_exposure_mean_nm[k] - p.step_nm);
  }
}

}  // namespace
}  // namespace piezoshift::calibration

int main(int argc, char** argv) {
  const char* seed_env = std::getenv("DIAG_SEED");
  const std::uint64_t seed = seed_env ? std::strtoull(seed_env, nullptr, 10) : 1;
  std::vector<std::string> names(argv + 1, argv + argc);
  if (names.empty())
    names = {"default", "thick-plate", "payload", "contact-spread"};
  for (const std::string& n : names)
    piezoshift::calibration::trace(n, seed);
  return 0;
}
