#pragma once
// The fringe scans' stage on the twin's bench (scan_stage.hpp): rig::Bench, the loop `run` ships
// on a simulated clock, the plate's true pose to the camera at every tick of an exposure. The
// geometry is the twin's own.
#include "piezoshift/instrument/scan_stage.hpp"
#include "piezoshift/rig/bench.hpp"

namespace piezoshift::instrument {

class BenchScanStage final : public ScanStage {
 public:
  explicit BenchScanStage(rig::Bench& bench) : bench_(bench) {}

  void set_controller(const control::SemiClosedLoopParams& params) override {
    bench_.set_controller(params);
  }
  control::SemiClosedLoopParams controller() const override { return bench_.controller_params(); }
  void drive_actuators(const control::Vec3& s_um) override { bench_.drive_actuators(s_um); }
  void drive_points(const control::Vec3& zd_um) override { bench_.drive_points(zd_um); }
  void settle(double duration_s) override { bench_.run(duration_s); }
  double time_s() const override { return bench_.time_s(); }
  std::string fault() const override;
  void mark_pose_origin() override { origin_ = raw_pose(); }
  std::string expose(camera::Camera& camera, double exposure_s, ScanExposure& e) override;
  const std::array<kinematics::PlatePoint, 3>& actuators() const override {
    return bench_.twin().model().geometry.actuators;
  }
  const std::array<kinematics::PlatePoint, 3>& points() const override {
    return bench_.twin().model().geometry.points;
  }

 private:
  camera::PlatePose raw_pose() const;
  camera::PlatePose plate_pose() const;

  rig::Bench& bench_;
  camera::PlatePose origin_{};
};

}  // namespace piezoshift::instrument
