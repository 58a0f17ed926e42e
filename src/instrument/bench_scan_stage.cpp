#include "piezoshift/instrument/bench_scan_stage.hpp"

#include <fmt/core.h>

namespace piezoshift::instrument {

std::string BenchScanStage::fault() const {
  if (!bench_.faulted())
    return "";
  return fmt::format("the safety supervisor tripped ({}, channel {})",
                     runtime::to_string(bench_.fault().reason), bench_.fault().channel + 1);
}

camera::PlatePose BenchScanStage::raw_pose() const {
  const plant::TwinTruth& t = bench_.twin().truth();
  return {bench_.time_s(), bench_.twin().fringe_piston_nm(), t.theta_x_urad, t.theta_y_urad};
}

camera::PlatePose BenchScanStage::plate_pose() const {
  return camera::relative_to(raw_pose(), origin_);
}

std::string BenchScanStage::expose(camera::Camera& camera, double exposure_s, ScanExposure& e) {
  const double t0 = bench_.time_s();
  e.saturated_mask = bench_.last_output().saturated_mask;
  e.trigger_time_s = t0;
  if (!camera.trigger(t0))
    return "the camera refused the trigger: " + camera.message();
  camera.observe_plate(plate_pose());
  const double end_s = t0 + exposure_s;
  // the truth as the camera integrates it: the mean over the exposure's ticks and its start
  control::Vec3 sgs{}, truth = bench_.twin().truth().points_um;
  int n = 0;
  while (bench_.time_s() < end_s - 1e-9) {
    bench_.run(bench_.sample_time_s());
    camera.observe_plate(plate_pose());
    for (std::size_t i = 0; i < 3; ++i) {
      sgs[i] += bench_.last_output().feedback_um[i];
      truth[i] += bench_.twin().truth().points_um[i];
    }
    ++n;
  }
  e.has_truth = true;
  for (std::size_t j = 0; j < 3; ++j) {
    e.truth_points_um[j] = truth[j] / (n + 1);
    e.sgs_um[j] = sgs[j] / n;
  }
  return "";
}

}  // namespace piezoshift::instrument
