// A loop calibrated outside its stable region: kp 5, ki 3, kd 2 ran `run --step-um 5`
// with one point of the plate swinging between 2.3 and 7.0 um and no fault. Such gains are
// refused at load (tests/calibration/controller_ranges_test.cpp); set anyway, the supervisor's
// oscillation rule trips within a stated time, on the shipping loop.
#include <gtest/gtest.h>

#include "piezoshift/rig/bench.hpp"

namespace piezoshift::rig {
namespace {

TEST(UnstableLoop, TheSupervisorNamesAnOscillationWithinTwentyMilliseconds) {
  control::SemiClosedLoopParams unstable;
  unstable.gains = {5.0, 3.0, 2.0};
  Bench bench(config::ProjectConfig{}, unstable, 1);
  bench.drive_points(Vec3{5.0, 5.0, 5.0});
  bench.run(0.5);
  ASSERT_TRUE(bench.faulted());
  EXPECT_EQ(bench.fault().reason, runtime::FaultReason::kOscillation);
  // The limit cycle has a 4-tick period (250 Hz, where the phase runs out, docs/calibration.md):
  // 8 reversals in 16 ticks after it starts.
  EXPECT_LE(bench.fault().tick, 20U);
  RecordProperty("oscillation_fault_tick", std::to_string(bench.fault().tick));
}

TEST(UnstableLoop, ThePapersGainsStepAndHoldWithoutAnOscillationFault) {
  Bench bench(config::ProjectConfig{}, control::SemiClosedLoopParams{}, 1);
  for (const double z : {10.0, 0.5, 8.0, 2.0, 5.0}) {
    bench.drive_points(Vec3{z, z, z});
    bench.run(0.3);
  }
  EXPECT_FALSE(bench.faulted()) << runtime::to_string(bench.fault().reason);
}

}  // namespace
}  // namespace piezoshift::rig
