#pragma once
// The stage a fringe scan drives (fringe_actuator_scan.hpp, fringe_piston_scan.hpp): poses held
// by the one control tick, settling, and one camera exposure at a held pose with the gauges'
// mean over it. Two stages implement it:
//
//   BenchScanStage  the twin through rig::Bench on a simulated clock (bench_scan_stage.hpp):
//                   `calibrate --interferometer fizeau --camera twin`
//   LoopScanStage   runtime::ControlLoop in a thread of its own through rig::LoopRig
//                   (loop_scan_stage.hpp): `--daq comedi:/dev/comediN` with a real camera, and
//                   the twin in real time or paced (`--daq sim-rt [--free-run]`)
//
// Where the loop knows the plate's true pose (the twin), expose() hands it to the camera at every
// tick of the exposure (observe_plate: the twin camera renders from it) and records its mean; on
// hardware the camera sees the plate itself and there is no truth.
#include <array>
#include <cstdint>
#include <string>

#include "piezoshift/camera/camera.hpp"
#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/kinematics/tripod.hpp"

namespace piezoshift::instrument {

//! One exposure at a held pose.
struct ScanExposure {
  double trigger_time_s = 0.0;      //!< the stage's clock at the exposure's first tick
  control::Vec3 sgs_um{};           //!< mean SGS feedback over the exposure's ticks
  std::uint8_t saturated_mask = 0;  //!< the PIDs at their limits when the exposure began
  bool has_truth = false;
  control::Vec3 truth_points_um{};  //!< the twin's P1..P3, mean over the exposure (has_truth)
};

class ScanStage {
 public:
  virtual ~ScanStage() = default;
  //! The controller from the next tick on; std::invalid_argument when the loop cannot run it.
  virtual void set_controller(const control::SemiClosedLoopParams& params) = 0;
  virtual control::SemiClosedLoopParams controller() const = 0;
  //! Holds the stage: the PIDs alone on targets S (calibration stage 2).
  virtual void drive_actuators(const control::Vec3& s_um) = 0;
  //! Holds the stage: the whole controller on Z_d (calibration stage 3).
  virtual void drive_points(const control::Vec3& zd_um) = 0;
  virtual void settle(double duration_s) = 0;
  //! The stage's clock [s] (loop time).
  virtual double time_s() const = 0;
  //! The latched supervisor fault, or the loop's end, described; empty when none.
  virtual std::string fault() const = 0;
  //! From here on, the plate poses expose() hands the camera are relative to the present one
  //! (the scan's first frame is the fringes' datum).
  virtual void mark_pose_origin() = 0;
  //! Triggers camera at the next tick and runs through exposure_s, filling e; "" when the camera
  //! took the trigger, else why not (the ticks still run).
  virtual std::string expose(camera::Camera& camera, double exposure_s, ScanExposure& e) = 0;
  //! Where the actuators and the measurement points are (the tracker's and the scan's step).
  virtual const std::array<kinematics::PlatePoint, 3>& actuators() const = 0;
  virtual const std::array<kinematics::PlatePoint, 3>& points() const = 0;
};

}  // namespace piezoshift::instrument
