#include "piezoshift/instrument/fringe_calibration.hpp"

#include <fmt/core.h>

#include <chrono>

#include <Eigen/LU>

#include "piezoshift/calibration/fit_error.hpp"
#include "piezoshift/calibration/matrix_fit.hpp"
#include "piezoshift/calibration/pid_tuning.hpp"
#include "piezoshift/calibration/poly_fit.hpp"
#include "piezoshift/camera/make_camera.hpp"
#include "piezoshift/core/wall_time.hpp"
#include "piezoshift/instrument/bench_scan_stage.hpp"

namespace piezoshift::instrument {

namespace {

psi::FringeTrackerParams tracker(const FringeOptics& optics) {
  psi::FringeTrackerParams t;
  t.plate_m_per_px = optics.plate_m_per_px;
  return t;
}

// Stage 2: the three actuators' scans on one bench, their ends stage 2's poses. False (and the
// reason in out.validity) when a scan or the fit fails.
// An empty mask is found in the first scan's reference frames and kept for the scans after it.
bool stage2(ScanStage& stage, camera::Camera& camera, FringeOptics& optics,
            const FringeCalibrationOptions& o, const rig::Progress& progress,
            FringeCalibrationOutcome& out) {
  const double t0 = stage.time_s();
  for (std::size_t i = 0; i < 3; ++i) {
    FringeActuatorScanParams p;
    p.actuator = i;
    p.base_um = o.stages.matrix.base_um;
    p.move_um = o.stages.matrix.move_um;
    p.wavelength_nm = o.wavelength_nm;
    p.reference_step_um = 1e-3 * o.wavelength_nm / 8.0;
    p.max_pupil_step_nm = o.max_pupil_step_nm;
    p.settle_s = o.settle_s;
    p.pupil_radius_m = optics.pupil_radius_m;
    p.tracker = tracker(optics);
    FringeActuatorScanResult& r = out.actuator_scans[i];
    r = run_fringe_actuator_scan(stage, camera, optics.mask, p);
    if (r.pupil_from_modulation) {
      optics.mask = r.pupil;
      optics.plate_m_per_px = plate_m_per_px(r.pupil, optics.pupil_radius_m);
      out.pupil_from_modulation = true;
    }
    if (!r.validity.valid) {
      out.validity.fail(
          fmt::format("stage 2 (matrix A), actuator {}'s scan: {}", i + 1, r.validity.reason));
      return false;
    }
    const ScanMatrixPose m = matrix_pose(r);
    out.matrix.ds_um.push_back(m.ds_um);
    out.matrix.dz_um.push_back(m.dz_um);
    if (progress)
      progress(static_cast<double>(i + 1), 3.0, "matrix A from fringes");
  }
  out.stage2_simulated_s = stage.time_s() - t0;
  out.matrix.simulated_time_s = stage.time_s();
  try {
    out.matrix.fit = calibration::fit_transmission_matrix(out.matrix.ds_um, out.matrix.dz_um);
  } catch (const calibration::FitError& e) {
    out.validity.fail(fmt::format("stage 2 (matrix A): the scans cannot give A: {}", e.what()));
    return false;
  }
  return true;
}

// The plate's mean displacement at a pose as the gauges read it (S = A Z with p the identity).
// Stage 3's datum: the fringes give each frame's displacement from frame 0, and frame 0 (the
// plate at 0 V, the PIDs at their lower limit) sits wherever the stacks' history left it: on one
// stage after stage 2's moves, their remanence (0.11 um on the twin through the loop). The
// gauges' zero does not move with it, so p is the same whatever ran before.
double gauge_datum_um(const control::Mat3& a, const control::Vec3& sgs_um) {
  Eigen::Matrix3d m;
  Eigen::Vector3d s;
  for (int i = 0; i < 3; ++i) {
    s(i) = sgs_um[static_cast<std::size_t>(i)];
    for (int j = 0; j < 3; ++j)
      m(i, j) = a[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)];
  }
  return m.partialPivLu().solve(s).mean();
}

// Stage 3: the common scan with the gains and A in place, p the identity; every frame a point.
bool stage3(ScanStage& stage, camera::Camera& camera, const FringeOptics& optics,
            const FringeCalibrationOptions& o, const rig::Progress& progress,
            FringeCalibrationOutcome& out) {
  control::SemiClosedLoopParams params = stage.controller();
  params.polynomial = control::CubicPolynomial::identity();
  stage.set_controller(params);
  const double t0 = stage.time_s();
  FringePistonScanParams p;
  p.max_um = o.stages.polynomial.max_um;
  p.wavelength_nm = o.wavelength_nm;
  p.reference_step_um = 1e-3 * o.wavelength_nm / 8.0;
  p.max_pupil_step_nm = o.max_pupil_step_nm;
  p.settle_s = o.settle_s;
  p.pupil_radius_m = optics.pupil_radius_m;
  p.tracker = tracker(optics);
  out.piston_scan = run_fringe_piston_scan(stage, camera, optics.mask, p);
  const FringePistonScanResult& r = out.piston_scan;
  out.stage3_simulated_s = stage.time_s() - t0;
  if (!r.validity.valid) {
    out.validity.fail(
        fmt::format("stage 3 (polynomial p), the common scan: {}", r.validity.reason));
    return false;
  }
  calibration::PolynomialIdentificationResult& poly = out.polynomial;
  out.stage3_datum_um = gauge_datum_um(params.matrix.a, r.poses.front().sgs_um);
  for (const FringeScanPose& q : r.poses) {
    if (q.saturated_mask != 0) {
      ++poly.saturated_points;
      continue;
    }
    poly.command_um.push_back(q.target_um[0]);
    poly.measured_um.push_back(out.stage3_datum_um +
                               (q.points_um[0] + q.points_um[1] + q.points_um[2]) / 3.0);
  }
  poly.simulated_time_s = stage.time_s();
  if (progress)
    progress(1.0, 1.0, "polynomial p from fringes");
  try {
    poly.fit = calibration::fit_cubic_polynomial(poly.measured_um, poly.command_um);
  } catch (const calibration::FitError& e) {
    out.validity.fail(fmt::format("stage 3 (polynomial p): the scan cannot give p: {}", e.what()));
    return false;
  }
  return true;
}

}  // namespace

FringeOptics twin_optics(const camera::TwinScene& scene) {
  return {scene.mask, scene.fizeau.pupil_radius_m,
          scene.fizeau.pupil_radius_m / scene.fizeau.pupil_radius_px};
}

FringeCalibrationOutcome calibrate_from_fringes(const config::ProjectConfig& config,
                                                const control::SemiClosedLoopParams& base,
                                                std::uint64_t seed, camera::Camera& camera,
                                                const FringeOptics& optics,
                                                const FringeCalibrationOptions& o,
                                                const rig::Progress& progress) {
  const auto w0 = std::chrono::steady_clock::now();
  FringeCalibrationOutcome out;
  // Stage 1 as calibration::calibrate() runs it: no interferometer in it.
  out.controller = base;
  out.controller.gains_sample_time_s = base.sample_time_s;
  if (o.stages.holding_gains) {
    out.controller.gains = *o.stages.holding_gains;
  } else {
    calibration::PidTuningOptions pid_tuning = o.stages.pid_tuning;
    pid_tuning.limits = o.stages.limits;
    out.pid = calibration::tune_pid(config, base, seed, pid_tuning, progress);
    out.controller.gains =
        o.stages.pid == calibration::PidChoice::kPaper ? out.pid.paper.gains : out.pid.best.gains;
  }
  out.controller.polynomial = control::CubicPolynomial::identity();
  out.controller.matrix = control::TransmissionMatrix::identity();
  const rig::BenchOptions bo{rig::Feedback::kGauges, o.stages.limits};
  FringeOptics found = optics;
  bool ok = false;
  {
    rig::Bench bench(config, out.controller, seed + 1, bo);
    BenchScanStage stage(bench);
    ok = stage2(stage, camera, found, o, progress, out);
  }
  if (ok) {
    out.controller.matrix = out.matrix.fit.a;
    rig::Bench bench(config, out.controller, seed + 2, bo);
    BenchScanStage stage(bench);
    ok = stage3(stage, camera, found, o, progress, out);
  }
  if (ok)
    out.controller.polynomial = out.polynomial.fit.p;
  out.wall_time_s = core::seconds_since(w0);
  return out;
}

FringeCalibrationOutcome calibrate_from_fringes(ScanStage& stage, camera::Camera& camera,
                                                const FringeOptics& optics,
                                                const FringeCalibrationOptions& o,
                                                const rig::Progress& progress) {
  const auto w0 = std::chrono::steady_clock::now();
  FringeCalibrationOutcome out;
  out.controller = stage.controller();
  out.controller.gains_sample_time_s = out.controller.sample_time_s;
  out.controller.polynomial = control::CubicPolynomial::identity();
  out.controller.matrix = control::TransmissionMatrix::identity();
  stage.set_controller(out.controller);
  FringeOptics found = optics;
  bool ok = stage2(stage, camera, found, o, progress, out);
  if (ok) {
    out.controller.matrix = out.matrix.fit.a;
    stage.set_controller(out.controller);
    ok = stage3(stage, camera, found, o, progress, out);
  }
  if (ok)
    out.controller.polynomial = out.polynomial.fit.p;
  out.wall_time_s = core::seconds_since(w0);
  return out;
}

FringeCalibrationOptions fringe_calibration_options(bool search_gains,
                                                    const runtime::SafetyLimits& limits) {
  FringeCalibrationOptions o;
  // --pid paper keeps the paper's gains (as `run` calibrates the twin; the XL-80 path's grid
  // would keep the same gains); search runs the grid.
  if (search_gains)
    o.stages.pid = calibration::PidChoice::kSearch;
  else
    o.stages = calibration::CalibrationOptions::paper_gains_only();
  o.stages.limits = limits;
  return o;
}

std::size_t frames_read(const FringeCalibrationOutcome& r) {
  std::size_t n = r.piston_scan.poses.size();
  for (const FringeActuatorScanResult& s : r.actuator_scans)
    n += s.poses.size();
  return n;
}

FringeCalibrationOutcome calibrate_twin_from_fringes(const camera::InstrumentConfig& config,
                                                     std::uint64_t seed,
                                                     const psi::SurfaceSpec& surface,
                                                     const FringeCalibrationOptions& options,
                                                     const rig::Progress& progress) {
  const camera::TwinScene scene = camera::make_twin_scene(
      surface,
      camera::measurement_optics(config.camera.settings, config.camera.pupil_radius_m,
                                 options.wavelength_nm),
      seed);
  const std::unique_ptr<camera::Camera> cam = camera::make_camera("twin", config.camera, &scene);
  control::SemiClosedLoopParams base;
  base.sample_time_s = config.installation.project.twin.daq.sample_time_s;
  return calibrate_from_fringes(config.installation.project, base, seed, *cam, twin_optics(scene),
                                options, progress);
}

}  // namespace piezoshift::instrument
