// The one control tick (control_cycle.hpp): the same sequence against any backend, here the
// closed-form fake plant, so each number below follows from the header's equations.
#include "piezoshift/runtime/control_cycle.hpp"

#include <gtest/gtest.h>

#include "fake_backend.hpp"

namespace piezoshift::runtime {
namespace {

CycleTime at(std::uint64_t k) {
  return CycleTime{k, static_cast<std::int64_t>(k) * 1'000'000, 1'000'000};
}

TEST(ControlCycle, OpenLoopVoltsGoOutThroughTheSlewLimitAndTheTimingContract) {
  testing::FakeBackend daq;
  daq.activate();
  ControlCycle cycle(control::SemiClosedLoopParams{}, SafetyLimits{});
  cycle.drive_open_loop(Vec3{10.0, 10.0, 10.0});
  const CycleSample& s0 = cycle.step(daq, at(0), false);
  // 1500 V/s over 1 ms: the first output is 1.5 V, written (staged) this tick.
  EXPECT_DOUBLE_EQ(s0.supervisor.ao_V[0], 1.5);
  EXPECT_DOUBLE_EQ(daq.last_written[0], 1.5);
  EXPECT_TRUE(s0.supervisor.limited);
  // Read k applies the outputs staged at k - 1 after sampling: the AI of tick 1 is still 0.
  const CycleSample& s1 = cycle.step(daq, at(1), false);
  EXPECT_DOUBLE_EQ(s1.ai_V[0], 0.0);
  EXPECT_DOUBLE_EQ(s1.supervisor.ao_V[0], 3.0);
  EXPECT_GT(cycle.step(daq, at(2), false).ai_V[0], 0.0);
  EXPECT_EQ(cycle.mode(), DriveMode::kOpenLoop);
}

TEST(ControlCycle, HandsOverToTheClosedLoopWithoutABump) {
  testing::FakeBackend daq;
  daq.activate();
  ControlCycle cycle(control::SemiClosedLoopParams{}, SafetyLimits{});
  cycle.drive_open_loop(Vec3{4.0, 4.0, 4.0});
  std::uint64_t k = 0;
  for (; k < 200; ++k)
    cycle.step(daq, at(k), false);
  const Vec3 held = cycle.last().supervisor.ao_V;
  ASSERT_DOUBLE_EQ(held[1], 4.0);
  // The target is what the gauges read now: the PIDs restart from the command the outputs hold,
  // so the first closed-loop output stays within one PID increment of 4 V.
  cycle.drive_actuators(cycle.last().controller.feedback_um);
  const CycleSample& s = cycle.step(daq, at(k), false);
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_NEAR(s.supervisor.ao_V[i], held[i], 0.01) << i;
  EXPECT_FALSE(cycle.supervisor().faulted());
}

TEST(ControlCycle, AFaultRampsToZeroAndClearRestartsFromZeroVolts) {
  testing::FakeBackend daq;
  daq.activate();
  ControlCycle cycle(control::SemiClosedLoopParams{}, SafetyLimits{});
  cycle.drive_points(Vec3{5.0, 5.0, 5.0});
  std::uint64_t k = 0;
  for (; k < 100; ++k)
    cycle.step(daq, at(k), false);
  daq.fail_reads = true;
  cycle.step(daq, at(k++), false);
  ASSERT_TRUE(cycle.supervisor().faulted());
  EXPECT_EQ(cycle.supervisor().fault().reason, FaultReason::kDaqRead);
  daq.fail_reads = false;
  // 500 V/s safe ramp: from at most 10 V, 0 V within 20 ticks.
  for (int n = 0; n < 25; ++n)
    cycle.step(daq, at(k++), false);
  EXPECT_TRUE(cycle.supervisor().outputs_at_zero());
  EXPECT_TRUE(cycle.clear_fault());
  EXPECT_FALSE(cycle.clear_fault());
  EXPECT_DOUBLE_EQ(cycle.controller().channel(0).state().output, 0.0);
}

TEST(ControlCycle, EachTickCarriesTheDemandOfItsModeInItsOwnUnitAndZeroInTheOthers) {
  testing::FakeBackend daq;
  daq.activate();
  ControlCycle cycle(control::SemiClosedLoopParams{}, SafetyLimits{});
  const Vec3 volts{1.0, 2.0, 3.0};
  cycle.drive_open_loop(volts);
  const CycleSample& v = cycle.step(daq, at(0), false);
  EXPECT_EQ(v.open_loop_V, volts);
  EXPECT_EQ(v.controller.dac_V, volts);
  EXPECT_EQ(v.zd_um, Vec3{});
  EXPECT_EQ(v.actuator_target_um, Vec3{});
  const Vec3 s_um{2.0, 4.0, 6.0};
  cycle.drive_actuators(s_um);
  const CycleSample& s = cycle.step(daq, at(1), false);
  EXPECT_EQ(s.actuator_target_um, s_um);
  EXPECT_EQ(s.controller.target_um, s_um);
  EXPECT_EQ(s.zd_um, Vec3{});
  EXPECT_EQ(s.open_loop_V, Vec3{});
  const Vec3 zd_um{5.0, 5.0, 5.0};
  cycle.drive_points(zd_um);
  const CycleSample& z = cycle.step(daq, at(2), false);
  EXPECT_EQ(z.zd_um, zd_um);
  EXPECT_EQ(z.actuator_target_um, Vec3{});
  EXPECT_EQ(z.open_loop_V, Vec3{});
  EXPECT_EQ(cycle.mode(), DriveMode::kPoints);
}

TEST(ControlCycle, ARefusedControllerIsOneSentenceForEveryCaller) {
  EXPECT_EQ(refused_controller_message("bench", control::ParamsProblem::kOutputLimits),
            "bench: the loop refused the controller: output_min_um is not below output_max_um");
}

}  // namespace
}  // namespace piezoshift::runtime
