#include "piezoshift/psi/error_budget.hpp"

#include <cmath>
#include <functional>
#include <numbers>

#include <fmt/core.h>

#include "piezoshift/plant/random.hpp"
#include "piezoshift/psi/analysis.hpp"
#include "piezoshift/psi/fizeau_simulation.hpp"

namespace piezoshift::psi {
namespace {

struct Trial {
  std::vector<std::vector<PoseSample>> poses;  // per frame
  CameraParams camera;
};

}  // namespace

ErrorBudget error_budget(const BudgetParams& bp, std::span<const Algorithm> algorithms) {
  ErrorBudget out;
  out.algorithms.assign(algorithms.begin(), algorithms.end());
  FizeauParams fz;
  fz.width_px = fz.height_px = bp.size_px;
  fz.pupil_radius_px = 0.45 * bp.size_px;
  fz.pupil_radius_m = bp.pupil_radius_m;
  fz.wavelength_nm = bp.wavelength_nm;
  const Mask mask = disk_mask(bp.size_px, bp.size_px, fz.pupil_radius_px);
  plant::Rng surface_rng(bp.seed);
  SurfaceSpec spec;
  spec.roughness_rms_nm = 0.0;
  const Map truth = make_surface_nm(spec, mask, surface_rng);

  CameraParams clean;
  clean.shot_noise = false;
  clean.read_noise_e = 0.0;
  clean.bit_depth = 16;
  clean.exposure_s = bp.exposure_s;

  // Each source: (name, magnitude, how it perturbs frame k's poses and the camera)
  using Perturb = std::function<void(int k, double step_nm, plant::Rng&, std::vector<PoseSample>&,
                                     CameraParams&)>;
  struct Source {
    std::string name, magnitude;
    Perturb perturb;
  };
  const std::vector<Source> sources{
      {"none", "-", [](int, double, plant::Rng&, std::vector<PoseSample>&, CameraParams&) {}},
      {"step gain", fmt::format("{:+.1f} %", 100.0 * bp.step_gain_error),
       [&](int k, double step, plant::Rng&, std::vector<PoseSample>& p, CameraParams&) {
         for (PoseSample& s : p)
           s.piston_nm += bp.step_gain_error * k * step;
       }},
      {"step noise", fmt::format("{:.2f} nm rms", bp.step_noise_nm),
       [&](int, double, plant::Rng& rng, std::vector<PoseSample>& p, CameraParams&) {
         const double e = bp.step_noise_nm * rng.normal();
         for (PoseSample& s : p)
           s.piston_nm += e;
       }},
      {"tilt per frame", fmt::format("{:.3f} urad rms", bp.tilt_per_frame_urad),
       [&](int, double, plant::Rng& rng, std::vector<PoseSample>& p, CameraParams&) {
         const double tx = bp.tilt_per_frame_urad * rng.normal();
         const double ty = bp.tilt_per_frame_urad * rng.normal();
         for (PoseSample& s : p) {
           s.theta_x_urad += tx;
           s.theta_y_urad += ty;
         }
       }},
      {"vibration", fmt::format("{:.1f} nm at {:g} Hz", bp.vibration_nm, bp.vibration_hz),
       [&](int, double, plant::Rng& rng, std::vector<PoseSample>& p, CameraParams&) {
         const double ph = 2.0 * std::numbers::pi * rng.uniform();
         for (PoseSample& s : p)
           s.piston_nm +=
               bp.vibration_nm * std::sin(2.0 * std::numbers::pi * bp.vibration_hz * s.time_s + ph);
       }},
      {"intensity noise", fmt::format("{:.1f} % of mean", 100.0 * bp.intensity_noise),
       [&](int, double, plant::Rng&, std::vector<PoseSample>&, CameraParams& c) {
         c.read_noise_e = bp.intensity_noise * c.full_well_e * c.mean_fill;
       }},
      {"quantisation", fmt::format("{} bit", bp.quantization_bits),
       [&](int, double, plant::Rng&, std::vector<PoseSample>&, CameraParams& c) {
         c.bit_depth = bp.quantization_bits;
       }},
  };

  AnalysisOptions ao;
  ao.wavelength_nm = bp.wavelength_nm;
  ao.zernike_terms = 37;
  for (std::size_t si = 0; si < sources.size(); ++si) {
    BudgetRow row{sources[si].name, sources[si].magnitude, {}};
    for (std::size_t ai = 0; ai < algorithms.size(); ++ai) {
      const Algorithm a = algorithms[ai];
      const int nf = required_frames(a) > 0 ? required_frames(a) : 5;
      const double step_nm = nominal_step_rad(a) * bp.wavelength_nm / (4.0 * std::numbers::pi);
      plant::Rng rng(bp.seed * 1000003u + si * 101u + ai);
      double acc = 0.0;
      for (int t = 0; t < bp.trials; ++t) {
        std::vector<Map> frames;
        for (int k = 0; k < nf; ++k) {
          std::vector<PoseSample> poses;
          constexpr int kSamples = 11;  // across the exposure, for the vibration
          for (int s = 0; s < kSamples; ++s)
            poses.push_back({bp.exposure_s * s / (kSamples - 1), k * step_nm, 0.0, 0.0});
          CameraParams cam = clean;
          sources[si].perturb(k, step_nm, rng, poses, cam);
          frames.push_back(render_frame(truth, mask, fz, cam, poses, rng));
        }
        ao.phase = PhaseOptions{};
        ao.phase.algorithm = a;
        const Analysis an = analyze_frames(frames, mask, ao);
        acc += surface_error_rms_nm(an.surface_nm, truth, mask);
      }
      row.rms_nm.push_back(acc / bp.trials);
    }
    out.rows.push_back(std::move(row));
  }
  return out;
}

std::string format_budget_table(const ErrorBudget& b) {
  std::string s = fmt::format("{:<16} {:<20}", "source", "magnitude");
  for (const Algorithm a : b.algorithms)
    s += fmt::format(" {:>10}", algorithm_name(a));
  s += "\n";
  for (const BudgetRow& r : b.rows) {
    s += fmt::format("{:<16} {:<20}", r.source, r.magnitude);
    for (const double v : r.rms_nm)
      s += fmt::format(" {:>10.3f}", v);
    s += "\n";
  }
  return s + "(surface RMS error [nm], piston and tilt removed, mean over trials)\n";
}

}  // namespace piezoshift::psi
