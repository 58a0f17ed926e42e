#include "piezoshift/instrument/loop_scan_stage.hpp"

#include <algorithm>
#include <cmath>

namespace piezoshift::instrument {

camera::PlatePose LoopScanStage::pose_of(const runtime::HostSample& h) const {
  const kinematics::PlatePose q = points_.forward({h.truth_um[0], h.truth_um[1], h.truth_um[2]});
  return {h.t_s, 1000.0 * q.z_um + h.fringe_drift_nm, q.theta_x_urad, q.theta_y_urad};
}

void LoopScanStage::mark_pose_origin() {
  const runtime::HostSample& h = rig_.last_sample();
  origin_ = h.has_truth != 0 ? pose_of(h) : camera::PlatePose{};
}

std::string LoopScanStage::expose(camera::Camera& camera, double exposure_s, ScanExposure& e) {
  const control::SemiClosedLoopParams params = rig_.controller();
  e.saturated_mask = rig_.last_sample().saturated_mask;
  // As the bench: the exposure's start and then each of its ticks (the last one at or past its end)
  const auto ticks = static_cast<std::uint64_t>(
      std::max(1.0, std::ceil(exposure_s / params.sample_time_s - 1e-6)));
  std::string refused;
  std::uint64_t n = 0;
  control::Vec3 sgs{}, truth{};
  e.has_truth = true;
  const std::function<void(const runtime::HostSample&)> each = [&](const runtime::HostSample& h) {
    if (n == 0) {
      e.trigger_time_s = h.t_s;
      if (!camera.trigger(h.t_s))
        refused = "the camera refused the trigger: " + camera.message();
    } else {
      for (std::size_t i = 0; i < 3; ++i)
        sgs[i] += params.scaling[i].sgs_to_um(h.sgs_V[i]);
    }
    e.has_truth = e.has_truth && h.has_truth != 0;
    if (h.has_truth != 0) {
      camera.observe_plate(camera::relative_to(pose_of(h), origin_));
      for (std::size_t j = 0; j < 3; ++j)
        truth[j] += h.truth_um[j];
    }
    ++n;
  };
  rig_.follow(ticks + 1, each);
  if (n < 2) {
    e.has_truth = false;
    return refused.empty() ? "the loop ended during the exposure" : refused;
  }
  for (std::size_t j = 0; j < 3; ++j) {
    e.sgs_um[j] = sgs[j] / static_cast<double>(n - 1);
    e.truth_points_um[j] = truth[j] / static_cast<double>(n);
  }
  return refused;
}

}  // namespace piezoshift::instrument
