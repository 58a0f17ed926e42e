#include "piezoshift/instrument/fringe_actuator_scan.hpp"

#include "piezoshift/instrument/fringe_piston_scan.hpp"

#include <fmt/core.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/core/wall_time.hpp"
#include "piezoshift/instrument/measurement.hpp"

namespace piezoshift::instrument {

namespace {

using Clock = std::chrono::steady_clock;
using core::seconds_since;

// The truth relative to frame 0, as the fringes are.
void truth_from_first_frame(std::vector<FringeScanPose>& poses) {
  if (poses.empty())
    return;
  const control::Vec3 z0 = poses.front().truth_points_um;
  for (FringeScanPose& q : poses)
    for (std::size_t j = 0; j < 3; ++j)
      q.truth_points_um[j] -= z0[j];
}

// The scan's state between poses: the bench, the camera, the tracker and what was taken.
class Scan {
 public:
  Scan(rig::Bench& bench, camera::Camera& camera, const psi::Mask& mask,
       const FringeActuatorScanParams& p,
       const std::function<void(rig::Bench&, const FringeScanPose&)>& at_pose)
      : bench_(bench),
        camera_(camera),
        p_(p),
        at_pose_(at_pose),
        tracker_(mask, tracker_params(bench, p)) {}

  bool ok() const { return r_.validity.valid; }
  FringeActuatorScanResult& result() { return r_; }

  void start() {
    origin_ = raw_pose();
    camera_.start();
  }

  // One pose: drive (the inner loops alone, or the full controller to the points), settle,
  // expose, track.
  void take(const control::Vec3& target_um, bool reference, double settle_s,
            bool drive_points = false) {
    if (drive_points)
      bench_.drive_points(target_um);
    else
      bench_.drive_actuators(target_um);
    bench_.run(settle_s);
    if (bench_.faulted()) {
      r_.validity.fail(fmt::format("the safety supervisor tripped ({}, channel {})",
                                   runtime::to_string(bench_.fault().reason),
                                   bench_.fault().channel + 1));
      return;
    }
    FringeScanPose pose;
    pose.frame = r_.poses.size();
    pose.reference = reference;
    pose.target_um = target_um;
    pose.saturated_mask = bench_.last_output().saturated_mask;
    expose(pose);
    if (!ok())
      return;
    r_.poses.push_back(pose);
    track();
    if (ok() && at_pose_)
      at_pose_(bench_, r_.poses.back());
  }

 private:
  static psi::FringeTrackerParams tracker_params(const rig::Bench& bench,
                                                 const FringeActuatorScanParams& p) {
    psi::FringeTrackerParams t = p.tracker;
    t.window_frames = p.reference_frames;
    t.wavelength_nm = p.wavelength_nm;
    t.points = bench.twin().model().geometry.points;
    t.first_direction = +1;  // the reference ascends
    return t;
  }

  camera::PlatePose raw_pose() const {
    const plant::TwinTruth& t = bench_.twin().truth();
    return {bench_.time_s(), bench_.twin().fringe_piston_nm(), t.theta_x_urad, t.theta_y_urad};
  }
  camera::PlatePose plate_pose() const {
    const camera::PlatePose r = raw_pose();
    return {r.time_s, r.piston_nm - origin_.piston_nm, r.theta_x_urad - origin_.theta_x_urad,
            r.theta_y_urad - origin_.theta_y_urad};
  }

  // Triggers, ticks through the exposure feeding the camera each tick's pose, waits for the frame.
  void expose(FringeScanPose& pose) {
    const double t0 = bench_.time_s();
    if (!camera_.trigger(t0)) {
      r_.validity.fail(fmt::format("frame {}: the camera refused the trigger: {}", pose.frame,
                                   camera_.message()));
      return;
    }
    pose.time_s = t0;
    camera_.observe_plate(plate_pose());
    const double end_s = t0 + camera_.settings().exposure_s;
    // the truth as the camera integrates it: the mean over the exposure's ticks
    control::Vec3 sgs{}, truth = bench_.twin().truth().points_um;
    int n = 0;
    while (bench_.time_s() < end_s - 1e-9) {
      bench_.run(bench_.sample_time_s());
      camera_.observe_plate(plate_pose());
      for (std::size_t i = 0; i < 3; ++i) {
        sgs[i] += bench_.last_output().feedback_um[i];
        truth[i] += bench_.twin().truth().points_um[i];
      }
      ++n;
    }
    for (std::size_t j = 0; j < 3; ++j)
      pose.truth_points_um[j] = truth[j] / (n + 1);
    for (std::size_t i = 0; i < 3; ++i)
      pose.sgs_um[i] = sgs[i] / n;
    const camera::FrameStatus s = camera_.wait(frame_, p_.frame_timeout_s);
    if (s != camera::FrameStatus::kOk) {
      const std::string why = camera_.message();
      r_.validity.fail(fmt::format("frame {}: {}{}{}", pose.frame, camera::to_string(s),
                                   why.empty() ? "" : ": ", why));
    }
  }

  void track() {
    const auto w0 = Clock::now();
    std::vector<camera::Frame> one(1);
    one[0] = std::move(frame_);
    const std::vector<psi::FringePose> got = tracker_.push(frame_maps(one)[0]);
    frame_ = std::move(one[0]);
    r_.tracker_wall_s += seconds_since(w0);
    for (const psi::FringePose& g : got) {
      FringeScanPose& q = r_.poses.at(g.frame);
      q.valid = g.valid;
      q.reason = g.reason;
      for (std::size_t j = 0; j < 3; ++j)
        q.points_um[j] = g.points_um[j];
      if (!g.valid)
        r_.validity.fail(
            fmt::format("frame {}: the fringe tracker refused it: {}", g.frame, g.reason));
    }
  }

  rig::Bench& bench_;
  camera::Camera& camera_;
  const FringeActuatorScanParams& p_;
  const std::function<void(rig::Bench&, const FringeScanPose&)>& at_pose_;
  psi::FringeTracker tracker_;
  camera::PlatePose origin_{};
  camera::Frame frame_;
  FringeActuatorScanResult r_;
};

void check_frame_size(const camera::Camera& camera, const psi::Mask& mask, const char* what) {
  const camera::CameraSettings& cs = camera.settings();
  if (cs.width_px != mask.width || cs.height_px != mask.height)
    throw core::InputError(
        fmt::format("{}: camera {} gives {}x{} px frames, the pupil's mask is {}x{}", what,
                    camera.name(), cs.width_px, cs.height_px, mask.width, mask.height));
}

}  // namespace

std::string fringe_actuator_scan_problem(const FringeActuatorScanParams& p) {
  const auto pos = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (p.actuator > 2)
    return fmt::format("actuator {} is not 0, 1 or 2", p.actuator);
  if (!std::isfinite(p.base_um) || p.base_um < 0.0)
    return "base_um must be finite and >= 0";
  if (!pos(p.move_um))
    return "move_um must be finite and > 0";
  if (p.reference_frames < 3)
    return "reference_frames must be at least 3";
  if (!pos(p.wavelength_nm) || !pos(p.reference_step_um) || !pos(p.pupil_radius_m) ||
      !pos(p.frame_timeout_s))
    return "wavelength_nm, reference_step_um, pupil_radius_m and frame_timeout_s must be > 0";
  if (!pos(p.max_pupil_step_nm) || p.max_pupil_step_nm > p.wavelength_nm / 4.0)
    return "max_pupil_step_nm must be > 0 and below a quarter wave";
  if (!std::isfinite(p.settle_s) || p.settle_s < 0.0 || !std::isfinite(p.initial_settle_s) ||
      p.initial_settle_s < 0.0)
    return "settle_s and initial_settle_s must be finite and >= 0";
  if (p.base_um - (p.reference_frames - 1) * p.reference_step_um < 0.0)
    return "base_um must leave room below it for the reference's steps";
  return "";
}

double pupil_step_nm(const std::array<kinematics::PlatePoint, 3>& actuators, std::size_t i,
                     double leg_um, double pupil_radius_m) {
  kinematics::PointDisplacements legs{};
  legs[i] = leg_um;
  const kinematics::PlatePose q = kinematics::TripodGeometry(actuators).forward(legs);
  // z + theta . r over the pupil's disk peaks at its edge: |z| + R |theta| (urad x m = 1e3 nm)
  return 1000.0 * std::fabs(q.z_um) +
         1e3 * pupil_radius_m * std::hypot(q.theta_x_urad, q.theta_y_urad);
}

ScanMatrixPose matrix_pose(const FringeActuatorScanResult& scan) {
  if (!scan.validity.valid || scan.poses.size() <= scan.base_pose + 1)
    throw std::invalid_argument("matrix_pose: the scan is not valid or has no move: " +
                                scan.validity.reason);
  const FringeScanPose& b = scan.poses[scan.base_pose];
  const FringeScanPose& e = scan.poses.back();
  ScanMatrixPose m;
  for (std::size_t j = 0; j < 3; ++j) {
    m.ds_um[j] = e.sgs_um[j] - b.sgs_um[j];
    m.dz_um[j] = e.points_um[j] - b.points_um[j];
  }
  return m;
}

FringeActuatorScanResult run_fringe_actuator_scan(
    rig::Bench& bench, camera::Camera& camera, const psi::Mask& mask,
    const FringeActuatorScanParams& p,
    const std::function<void(rig::Bench&, const FringeScanPose&)>& at_pose) {
  if (const std::string why = fringe_actuator_scan_problem(p); !why.empty())
    throw core::InputError("fringe actuator scan: " + why);
  check_frame_size(camera, mask, "fringe actuator scan");
  const auto w0 = Clock::now();
  const double t0 = bench.time_s();
  Scan scan(bench, camera, mask, p, at_pose);
  FringeActuatorScanResult& r = scan.result();
  const auto& actuators = bench.twin().model().geometry.actuators;
  const double per_um = pupil_step_nm(actuators, p.actuator, 1.0, p.pupil_radius_m);
  r.moves = static_cast<int>(std::ceil(p.move_um * per_um / p.max_pupil_step_nm));
  r.leg_step_um = p.move_um / r.moves;
  r.predicted_pupil_step_nm = per_um * r.leg_step_um;

  const int w = p.reference_frames;
  const auto common = [](double s_um) { return control::Vec3{s_um, s_um, s_um}; };
  bench.drive_actuators(common(p.base_um - (w - 1) * p.reference_step_um));
  bench.run(p.initial_settle_s);
  scan.start();
  for (int k = 0; k < w && scan.ok(); ++k)
    scan.take(common(p.base_um + (k - w + 1) * p.reference_step_um), true,
              k == 0 ? 0.0 : p.settle_s);
  r.base_pose = static_cast<std::size_t>(w - 1);
  for (int m = 1; m <= r.moves && scan.ok(); ++m) {
    control::Vec3 s = common(p.base_um);
    s[p.actuator] += r.leg_step_um * m;
    scan.take(s, false, p.settle_s);
  }
  camera.stop();
  truth_from_first_frame(r.poses);
  r.simulated_time_s = bench.time_s() - t0;
  r.wall_time_s = seconds_since(w0);
  return std::move(r);
}

std::string fringe_piston_scan_problem(const FringePistonScanParams& p) {
  const auto pos = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (p.reference_frames < 3)
    return "reference_frames must be at least 3";
  if (!pos(p.wavelength_nm) || !pos(p.reference_step_um) || !pos(p.frame_timeout_s))
    return "wavelength_nm, reference_step_um and frame_timeout_s must be > 0";
  if (!pos(p.max_pupil_step_nm) || p.max_pupil_step_nm > p.wavelength_nm / 4.0)
    return "max_pupil_step_nm must be > 0 and below a quarter wave";
  if (!std::isfinite(p.settle_s) || p.settle_s < 0.0 || !std::isfinite(p.initial_settle_s) ||
      p.initial_settle_s < 0.0)
    return "settle_s and initial_settle_s must be finite and >= 0";
  if (!pos(p.max_um) || p.max_um <= (p.reference_frames - 1) * p.reference_step_um)
    return "max_um must be finite and beyond the reference's last pose";
  return "";
}

FringePistonScanResult run_fringe_piston_scan(rig::Bench& bench, camera::Camera& camera,
                                              const psi::Mask& mask,
                                              const FringePistonScanParams& p) {
  if (const std::string why = fringe_piston_scan_problem(p); !why.empty())
    throw core::InputError("fringe piston scan: " + why);
  check_frame_size(camera, mask, "fringe piston scan");
  const auto w0 = Clock::now();
  const double t0 = bench.time_s();
  // the actuator scan's machinery, with the fields a piston scan shares
  FringeActuatorScanParams sp;
  sp.reference_frames = p.reference_frames;
  sp.wavelength_nm = p.wavelength_nm;
  sp.frame_timeout_s = p.frame_timeout_s;
  sp.tracker = p.tracker;
  const std::function<void(rig::Bench&, const FringeScanPose&)> no_callback;  // Scan keeps a ref
  Scan scan(bench, camera, mask, sp, no_callback);
  const int w = p.reference_frames;
  const double top_ref_um = (w - 1) * p.reference_step_um;
  FringePistonScanResult r;
  r.moves = static_cast<int>(std::ceil(1000.0 * (p.max_um - top_ref_um) / p.max_pupil_step_nm));
  r.step_um = (p.max_um - top_ref_um) / r.moves;
  const auto common = [](double z_um) { return control::Vec3{z_um, z_um, z_um}; };
  bench.drive_points(common(0.0));
  bench.run(p.initial_settle_s);
  scan.start();
  for (int k = 0; k < w && scan.ok(); ++k)
    scan.take(common(k * p.reference_step_um), true, k == 0 ? 0.0 : p.settle_s, true);
  for (int m = 1; m <= r.moves && scan.ok(); ++m)
    scan.take(common(top_ref_um + r.step_um * m), false, p.settle_s, true);
  camera.stop();
  FringeActuatorScanResult& got = scan.result();
  r.poses = std::move(got.poses);
  r.tracker_wall_s = got.tracker_wall_s;
  r.validity = got.validity;
  truth_from_first_frame(r.poses);
  r.simulated_time_s = bench.time_s() - t0;
  r.wall_time_s = seconds_since(w0);
  return r;
}

}  // namespace piezoshift::instrument
