// instrument::LoopScanStage (loop_scan_stage.hpp): the fringe scans' stage on the real-time loop
// behind rig::LoopRig, here on the twin paced by the rig (deterministic). An exposure follows
// the loop's next ticks: the camera triggered at the first one's time and handed every tick's
// true plate pose from the marked origin, the gauges averaged over the ticks after the first.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "piezoshift/config/project_config.hpp"
#include "piezoshift/instrument/loop_scan_stage.hpp"
#include "piezoshift/plant/geometry.hpp"
#include "piezoshift/runtime/paced_clock.hpp"
#include "piezoshift/runtime/sim_backend.hpp"
#include "scripted_camera.hpp"

namespace piezoshift::instrument {
namespace {

TEST(LoopScanStage, AnExposureFollowsTheLoopsNextTicksAndSaysWhenTheCameraRefusesIt) {
  const config::ProjectConfig config;
  runtime::SimOptions so;
  so.design = config.design;
  so.twin = config.twin;
  so.seed = 3;
  runtime::SimBackend sim(so);
  sim.configure();
  runtime::PacedClock clock;
  control::SemiClosedLoopParams params;
  params.sample_time_s = 1e-3;
  rig::LoopRigOptions lo;
  lo.request_realtime = false;
  rig::LoopRig rig(sim, clock, &clock, params, runtime::SafetyLimits{}, lo);
  LoopScanStage stage(rig, plant::make_twin_geometry(config.twin.geometry));
  stage.drive_actuators({2.0, 2.0, 2.0});
  stage.settle(0.3);
  ASSERT_EQ(stage.fault(), "");
  stage.mark_pose_origin();
  ScriptedCamera cam;
  camera::CameraSettings cs;
  cs.exposure_s = 0.003;
  cam.configure(cs);

  const double before_s = stage.time_s();
  ScanExposure e;
  EXPECT_EQ(stage.expose(cam, cs.exposure_s, e), "");
  // Triggered at the loop's next tick, then its pose and the 3 ticks' after it, 1 ms apart: the
  // exposure the bench gives (BenchScanStage), on the loop's samples.
  EXPECT_NEAR(e.trigger_time_s, before_s + 1e-3, 1e-9);
  ASSERT_EQ(cam.exposures.size(), 1u);
  ASSERT_EQ(cam.exposures[0].size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_NEAR(cam.exposures[0][k].time_s, e.trigger_time_s + 1e-3 * static_cast<double>(k), 1e-9);
    // the plate held since the origin was marked: within the gauges' noise through the PIDs
    EXPECT_LT(std::fabs(cam.exposures[0][k].piston_nm), 5.0) << k;
  }
  EXPECT_NEAR(stage.time_s(), e.trigger_time_s + cs.exposure_s, 1e-9);
  EXPECT_TRUE(e.has_truth);
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_NEAR(e.sgs_um[i], 2.0, 0.01) << i;  // the PIDs hold S = 2 um
  camera::Frame f;
  EXPECT_EQ(cam.wait(f, 1.0), camera::FrameStatus::kOk);  // its exposure ended: the frame is in

  // A camera that refuses the trigger is named; the exposure's ticks still run.
  cam.refuse = true;
  ScanExposure r;
  const std::string why = stage.expose(cam, cs.exposure_s, r);
  EXPECT_NE(why.find("the camera refused the trigger: refusing"), std::string::npos) << why;
  EXPECT_NEAR(r.trigger_time_s, e.trigger_time_s + cs.exposure_s + 1e-3, 1e-9);
  EXPECT_NEAR(stage.time_s(), r.trigger_time_s + cs.exposure_s, 1e-9);
  EXPECT_EQ(cam.exposures.size(), 1u);
  rig.stop();
}

}  // namespace
}  // namespace piezoshift::instrument
