#pragma once
// The fringe scans' stage on the real-time loop (scan_stage.hpp): runtime::ControlLoop in a thread
// of its own behind rig::LoopRig, as the guided calibration drives it (`calibrate --interferometer
// fizeau --daq comedi:/dev/comediN|sim-rt`). The scan's thread may block (a frame's wait, the
// tracker's fit) while the loop holds the pose; on a PacedClock the loop waits for it instead.
//
// An exposure follows the loop's next ticks (LoopRig::follow): the camera is triggered at the
// first one's time, the gauges are averaged over the rest, and on the twin each tick's true plate
// pose (from its P1..P3 through the installation's geometry, plus the cavity's drift) goes to the
// camera. On hardware the software trigger leaves the host when the rig takes the first tick's
// sample, a millisecond or two after it: the pose is held and settled, so the gauges' mean over
// the exposure's ticks is the pose the camera saw.
#include "piezoshift/instrument/scan_stage.hpp"
#include "piezoshift/plant/geometry.hpp"
#include "piezoshift/rig/loop_rig.hpp"

namespace piezoshift::instrument {

class LoopScanStage final : public ScanStage {
 public:
  //! geometry: the installation's ([twin.geometry]).
  LoopScanStage(rig::LoopRig& rig, const plant::TwinGeometry& geometry)
      : rig_(rig), geometry_(geometry), points_(geometry.points) {}

  void set_controller(const control::SemiClosedLoopParams& params) override {
    rig_.set_controller(params);
  }
  control::SemiClosedLoopParams controller() const override { return rig_.controller(); }
  void drive_actuators(const control::Vec3& s_um) override { rig_.drive_actuators(s_um); }
  void drive_points(const control::Vec3& zd_um) override { rig_.drive_points(zd_um); }
  void settle(double duration_s) override { rig_.settle(duration_s); }
  double time_s() const override { return rig_.last_sample().t_s; }
  std::string fault() const override { return rig_.fault(); }
  void mark_pose_origin() override;
  std::string expose(camera::Camera& camera, double exposure_s, ScanExposure& e) override;
  const std::array<kinematics::PlatePoint, 3>& actuators() const override {
    return geometry_.actuators;
  }
  const std::array<kinematics::PlatePoint, 3>& points() const override { return geometry_.points; }

 private:
  //! The plate's true pose in a twin's sample (the fringes' piston: the plate's and the
  //! cavity's drift).
  camera::PlatePose pose_of(const runtime::HostSample& h) const;

  rig::LoopRig& rig_;
  plant::TwinGeometry geometry_;
  kinematics::TripodGeometry points_;  // P1..P3 -> the plate's pose
  camera::PlatePose origin_{};
};

}  // namespace piezoshift::instrument
