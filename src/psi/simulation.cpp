#include "piezoshift/psi/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/plant/random.hpp"
#include "piezoshift/rig/bench.hpp"

namespace piezoshift::psi {

SimulationResult simulate_psi(const config::ProjectConfig& config,
                              const control::SemiClosedLoopParams& controller,
                              const SimulationParams& p) {
  if (const std::string e = fizeau_problem(p.fizeau); !e.empty())
    throw core::InputError("psi simulate: " + e);
  if (const std::string e = camera_problem(p.camera); !e.empty())
    throw core::InputError("psi simulate: " + e);
  const int need = required_frames(p.algorithm);
  const int nf = p.frames > 0 ? p.frames : (need > 0 ? need : 5);
  if (need > 0 && nf != need)
    throw core::InputError(fmt::format("psi simulate: --frames {}: {} needs {}", nf,
                                       algorithm_name(p.algorithm), need));
  if (nf < 3 || nf > 64)
    throw core::InputError(fmt::format("psi simulate: --frames {}: must be in 3..64", nf));
  if (!(p.base_um > 0.0 && p.base_um < 11.0))
    throw core::InputError(
        fmt::format("psi simulate: base_um = {}: must be in (0, 11)", p.base_um));

  SimulationResult r;
  r.mask = disk_mask(p.fizeau.width_px, p.fizeau.height_px, p.fizeau.pupil_radius_px);
  plant::Rng rng(p.seed);
  r.truth_nm = make_surface_nm(p.surface, r.mask, rng);

  control::SemiClosedLoopParams cp = controller;
  cp.sample_time_s = config.twin.daq.sample_time_s;  // the gains re-expressed at the DAQ period
  rig::Bench bench(config, cp, p.seed);
  BenchStage stage(bench, p.base_um);
  AcquisitionParams ap;
  ap.frames = nf;
  ap.step_nm = nominal_step_rad(p.algorithm) * p.fizeau.wavelength_nm / (4.0 * std::numbers::pi);
  ap.on_target = p.on_target;
  ap.exposure_s = p.camera.exposure_s;
  r.acquisition = acquire(stage, ap);
  r.log = stage.log();

  // the camera noise draws are the same for the real and the ideal stage
  plant::Rng cam_rng(p.seed ^ 0x9e3779b97f4a7c15ull), ideal_rng(p.seed ^ 0x9e3779b97f4a7c15ull);
  auto mean = [](const std::vector<PoseSample>& v, auto field) {
    double s = 0.0;
    for (const PoseSample& x : v)
      s += x.*field;
    return s / static_cast<double>(v.size());
  };
  const FrameRecord& f0 = r.acquisition.frames.front();
  for (int k = 0; k < nf; ++k) {
    const FrameRecord& f = r.acquisition.frames[static_cast<std::size_t>(k)];
    r.frames.push_back(render_frame(r.truth_nm, r.mask, p.fizeau, p.camera, f.poses, cam_rng));
    const PoseSample ideal{0.0, k * ap.step_nm, 0.0, 0.0};
    r.ideal_frames.push_back(
        render_frame(r.truth_nm, r.mask, p.fizeau, p.camera, std::span(&ideal, 1), ideal_rng));
    FrameStats st;
    st.step_nm = mean(f.poses, &PoseSample::piston_nm) - mean(f0.poses, &PoseSample::piston_nm);
    st.tip_urad =
        mean(f.poses, &PoseSample::theta_x_urad) - mean(f0.poses, &PoseSample::theta_x_urad);
    st.tilt_urad =
        mean(f.poses, &PoseSample::theta_y_urad) - mean(f0.poses, &PoseSample::theta_y_urad);
    const auto [lo, hi] = std::minmax_element(
        f.poses.begin(), f.poses.end(),
        [](const PoseSample& a, const PoseSample& b) { return a.piston_nm < b.piston_nm; });
    st.blur_nm = hi->piston_nm - lo->piston_nm;
    st.settle_s = f.on_target_time_s - f.move_time_s;
    st.on_target = f.on_target;
    r.frame_stats.push_back(st);
  }
  AnalysisOptions ao;
  ao.phase.algorithm = p.algorithm;
  ao.wavelength_nm = p.fizeau.wavelength_nm;
  r.analysis = analyze_frames(r.frames, r.mask, ao);
  r.ideal = analyze_frames(r.ideal_frames, r.mask, ao);
  r.error_rms_nm = surface_error_rms_nm(r.analysis.surface_nm, r.truth_nm, r.mask);
  r.ideal_error_rms_nm = surface_error_rms_nm(r.ideal.surface_nm, r.truth_nm, r.mask);
  const double d = r.error_rms_nm * r.error_rms_nm - r.ideal_error_rms_nm * r.ideal_error_rms_nm;
  r.stage_error_rms_nm = d > 0.0 ? std::sqrt(d) : 0.0;
  return r;
}

}  // namespace piezoshift::psi
