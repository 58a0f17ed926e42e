#include "piezoshift/instrument/fringe_actuator_scan.hpp"

#include "piezoshift/instrument/fringe_piston_scan.hpp"

#include <fmt/core.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/core/wall_time.hpp"
#include "piezoshift/instrument/bench_scan_stage.hpp"
#include "piezoshift/instrument/measurement.hpp"
#include "piezoshift/psi/pupil_detection.hpp"

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

// The scan's state between poses: the stage, the camera, the tracker and what was taken. With no
// mask the tracker waits for the reference frames and takes its pupil from their modulation.
class Scan {
 public:
  Scan(ScanStage& stage, camera::Camera& camera, const psi::Mask& mask,
       const FringeActuatorScanParams& p, const std::function<void(const FringeScanPose&)>& at_pose)
      : stage_(stage), camera_(camera), mask_(mask), p_(p), at_pose_(at_pose) {
    if (mask.size() != 0)
      tracker_.emplace(mask, tracker_params(mask, false));
  }

  bool ok() const { return r_.validity.valid; }
  FringeActuatorScanResult& result() { return r_; }
  const psi::Mask& mask() const { return mask_; }

  void start() {
    stage_.mark_pose_origin();
    camera_.start();
  }

  // One pose: drive (the inner loops alone, or the full controller to the points), settle,
  // expose, track.
  void take(const control::Vec3& target_um, bool reference, double settle_s,
            bool drive_points = false) {
    if (drive_points)
      stage_.drive_points(target_um);
    else
      stage_.drive_actuators(target_um);
    stage_.settle(settle_s);
    if (const std::string why = stage_.fault(); !why.empty()) {
      r_.validity.fail(why);
      return;
    }
    FringeScanPose pose;
    pose.frame = r_.poses.size();
    pose.reference = reference;
    pose.target_um = target_um;
    expose(pose);
    if (!ok())
      return;
    r_.poses.push_back(pose);
    track();
    if (ok() && at_pose_)
      at_pose_(r_.poses.back());
  }

 private:
  psi::FringeTrackerParams tracker_params(const psi::Mask& mask, bool found) const {
    psi::FringeTrackerParams t = p_.tracker;
    t.window_frames = p_.reference_frames;
    t.wavelength_nm = p_.wavelength_nm;
    t.points = stage_.points();
    t.first_direction = +1;  // the reference ascends
    if (found)               // a pupil found in the frames: its size on the plate is the given one
      t.plate_m_per_px = plate_m_per_px(mask, p_.pupil_radius_m);
    return t;
  }

  // Triggers, runs through the exposure (the stage feeds the camera), waits for the frame.
  void expose(FringeScanPose& pose) {
    ScanExposure e;
    if (const std::string why = stage_.expose(camera_, camera_.settings().exposure_s, e);
        !why.empty()) {
      r_.validity.fail(fmt::format("frame {}: {}", pose.frame, why));
      return;
    }
    pose.time_s = e.trigger_time_s;
    pose.saturated_mask = e.saturated_mask;
    pose.sgs_um = e.sgs_um;
    pose.has_truth = e.has_truth;
    pose.truth_points_um = e.truth_points_um;
    const camera::FrameStatus s = camera_.wait(frame_, p_.frame_timeout_s);
    if (s != camera::FrameStatus::kOk) {
      const std::string why = camera_.message();
      r_.validity.fail(fmt::format("frame {}: {}{}{}", pose.frame, camera::to_string(s),
                                   why.empty() ? "" : ": ", why));
    }
  }

  // The pupil from the reference frames' modulation, and the tracker on it, once they are in.
  bool find_pupil() {
    try {
      mask_ = psi::pupil_from_modulation(waiting_).mask;
    } catch (const std::invalid_argument& e) {
      r_.validity.fail(fmt::format("no pupil found in the reference frames: {}", e.what()));
      return false;
    }
    if (mask_.count() < 16) {
      r_.validity.fail(fmt::format(
          "{} pixels of pupil found in the reference frames' modulation (16 or more needed)",
          mask_.count()));
      return false;
    }
    r_.pupil_from_modulation = true;
    tracker_.emplace(mask_, tracker_params(mask_, true));
    return true;
  }

  void track() {
    const auto w0 = Clock::now();
    std::vector<camera::Frame> one(1);
    one[0] = std::move(frame_);
    psi::Map map = frame_maps(one)[0];
    frame_ = std::move(one[0]);
    std::vector<psi::FringePose> got;
    if (tracker_) {
      got = tracker_->push(map);
    } else {
      waiting_.push_back(std::move(map));
      if (waiting_.size() == static_cast<std::size_t>(p_.reference_frames)) {
        if (!find_pupil())
          return;
        for (const psi::Map& m : waiting_)
          for (const psi::FringePose& g : tracker_->push(m))
            got.push_back(g);
        waiting_.clear();
      }
    }
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

  ScanStage& stage_;
  camera::Camera& camera_;
  psi::Mask mask_;
  const FringeActuatorScanParams& p_;
  const std::function<void(const FringeScanPose&)>& at_pose_;
  std::optional<psi::FringeTracker> tracker_;
  std::vector<psi::Map> waiting_;  // the reference frames, while the pupil is not yet known
  camera::Frame frame_;
  FringeActuatorScanResult r_;
};

void check_frame_size(const camera::Camera& camera, const psi::Mask& mask, const char* what) {
  const camera::CameraSettings& cs = camera.settings();
  if (mask.size() != 0 && (cs.width_px != mask.width || cs.height_px != mask.height))
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

double plate_m_per_px(const psi::Mask& mask, double pupil_radius_m) {
  return pupil_radius_m / psi::pupil_of(mask).radius_px;
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
    ScanStage& stage, camera::Camera& camera, const psi::Mask& mask,
    const FringeActuatorScanParams& p, const std::function<void(const FringeScanPose&)>& at_pose) {
  if (const std::string why = fringe_actuator_scan_problem(p); !why.empty())
    throw core::InputError("fringe actuator scan: " + why);
  check_frame_size(camera, mask, "fringe actuator scan");
  const auto w0 = Clock::now();
  const double t0 = stage.time_s();
  Scan scan(stage, camera, mask, p, at_pose);
  FringeActuatorScanResult& r = scan.result();
  const double per_um = pupil_step_nm(stage.actuators(), p.actuator, 1.0, p.pupil_radius_m);
  r.moves = static_cast<int>(std::ceil(p.move_um * per_um / p.max_pupil_step_nm));
  r.leg_step_um = p.move_um / r.moves;
  r.predicted_pupil_step_nm = per_um * r.leg_step_um;

  const int w = p.reference_frames;
  const auto common = [](double s_um) { return control::Vec3{s_um, s_um, s_um}; };
  stage.drive_actuators(common(p.base_um - (w - 1) * p.reference_step_um));
  stage.settle(p.initial_settle_s);
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
  r.pupil = scan.mask();
  r.simulated_time_s = stage.time_s() - t0;
  r.wall_time_s = seconds_since(w0);
  return std::move(r);
}

FringeActuatorScanResult run_fringe_actuator_scan(
    rig::Bench& bench, camera::Camera& camera, const psi::Mask& mask,
    const FringeActuatorScanParams& params,
    const std::function<void(rig::Bench&, const FringeScanPose&)>& at_pose) {
  BenchScanStage stage(bench);
  std::function<void(const FringeScanPose&)> each;
  if (at_pose)
    each = [&](const FringeScanPose& q) { at_pose(bench, q); };
  return run_fringe_actuator_scan(stage, camera, mask, params, each);
}

std::string fringe_piston_scan_problem(const FringePistonScanParams& p) {
  const auto pos = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (p.reference_frames < 3)
    return "reference_frames must be at least 3";
  if (!pos(p.wavelength_nm) || !pos(p.reference_step_um) || !pos(p.frame_timeout_s) ||
      !pos(p.pupil_radius_m))
    return "wavelength_nm, reference_step_um, frame_timeout_s and pupil_radius_m must be > 0";
  if (!pos(p.max_pupil_step_nm) || p.max_pupil_step_nm > p.wavelength_nm / 4.0)
    return "max_pupil_step_nm must be > 0 and below a quarter wave";
  if (!std::isfinite(p.settle_s) || p.settle_s < 0.0 || !std::isfinite(p.initial_settle_s) ||
      p.initial_settle_s < 0.0)
    return "settle_s and initial_settle_s must be finite and >= 0";
  if (!pos(p.max_um) || p.max_um <= (p.reference_frames - 1) * p.reference_step_um)
    return "max_um must be finite and beyond the reference's last pose";
  return "";
}

FringePistonScanResult run_fringe_piston_scan(ScanStage& stage, camera::Camera& camera,
                                              const psi::Mask& mask,
                                              const FringePistonScanParams& p) {
  if (const std::string why = fringe_piston_scan_problem(p); !why.empty())
    throw core::InputError("fringe piston scan: " + why);
  check_frame_size(camera, mask, "fringe piston scan");
  const auto w0 = Clock::now();
  const double t0 = stage.time_s();
  // the actuator scan's machinery, with the fields a piston scan shares
  FringeActuatorScanParams sp;
  sp.reference_frames = p.reference_frames;
  sp.wavelength_nm = p.wavelength_nm;
  sp.frame_timeout_s = p.frame_timeout_s;
  sp.pupil_radius_m = p.pupil_radius_m;
  sp.tracker = p.tracker;
  const std::function<void(const FringeScanPose&)> no_callback;  // Scan keeps a reference
  Scan scan(stage, camera, mask, sp, no_callback);
  const int w = p.reference_frames;
  const double top_ref_um = (w - 1) * p.reference_step_um;
  FringePistonScanResult r;
  r.moves = static_cast<int>(std::ceil(1000.0 * (p.max_um - top_ref_um) / p.max_pupil_step_nm));
  r.step_um = (p.max_um - top_ref_um) / r.moves;
  const auto common = [](double z_um) { return control::Vec3{z_um, z_um, z_um}; };
  stage.drive_points(common(0.0));
  stage.settle(p.initial_settle_s);
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
  r.pupil = scan.mask();
  truth_from_first_frame(r.poses);
  r.simulated_time_s = stage.time_s() - t0;
  r.wall_time_s = seconds_since(w0);
  return r;
}

FringePistonScanResult run_fringe_piston_scan(rig::Bench& bench, camera::Camera& camera,
                                              const psi::Mask& mask,
                                              const FringePistonScanParams& p) {
  BenchScanStage stage(bench);
  return run_fringe_piston_scan(stage, camera, mask, p);
}

}  // namespace piezoshift::instrument
