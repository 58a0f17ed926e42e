#include "piezoshift/runtime/control_loop.hpp"

#include <atomic>
#include <cmath>

#include <gtest/gtest.h>

#include "fake_backend.hpp"
#include "piezoshift/runtime/fault_injection.hpp"
#include "piezoshift/runtime/fault_list.hpp"
#include "piezoshift/runtime/loop_status.hpp"

#include "allocation_counter.hpp"

namespace piezoshift::runtime {
namespace {

using testing::FakeBackend;

LoopConfig config(double rate_Hz, double duration_s) {
  LoopConfig c;
  c.rate_Hz = rate_Hz;
  c.duration_s = duration_s;
  return c;
}

TEST(ControlLoop, StepSettlesOnTargetAndRampsDownAtTheEnd) {
  FakeBackend daq;
  daq.configure();
  daq.activate();
  SimulatedClock clock;
  control::SemiClosedLoopParams params;  // the paper's controller
  ControlLoop loop(config(1000.0, 0.3), params, SafetyLimits{}, daq, clock,
                   SetpointProfile::step(8.0));
  const LoopResult r = loop.run();
  EXPECT_FALSE(r.fault_detected) << to_string(r.fault.reason) << " at " << r.fault.tick;
  EXPECT_EQ(r.stop_reason, StopReason::kDuration);
  const control::SemiClosedLoopController& c = loop.controller();
  const Vec3 s = c.actuator_targets(Vec3{8.0, 8.0, 8.0});
  // At tick 300 the targets had been held 0.3 s: the stage sits on S before the ramp.
  // The ramp then brings the outputs down at 0.5 V/ms: ceil(max ao / 0.5 V) ticks.
  double max_ao = 0.0;
  for (std::size_t i = 0; i < 3; ++i)
    max_ao = std::max(max_ao, s[i] / 0.9117 * 0.625);
  EXPECT_NEAR(r.max_output_V, max_ao, 0.01);
  const auto ramp_ticks = static_cast<std::uint64_t>(std::ceil(r.max_output_V / 0.5 - 1e-9));
  EXPECT_NEAR(static_cast<double>(r.ticks), 300.0 + static_cast<double>(ramp_ticks), 1.0);
  EXPECT_LE(r.max_output_slew_V_per_ms, 1.5 + 1e-9);
  EXPECT_EQ(loop.supervisor().state(), SupervisorState::kStopped);
  EXPECT_EQ(daq.last_written, Vec3{}) << "the last outputs staged are 0 V";
  // Period statistics of a simulated clock are exact: no lateness, no error, no overrun.
  EXPECT_EQ(loop.stats().overruns, 0U);
  EXPECT_EQ(loop.stats().period_error.max_ns(), 0);
  EXPECT_EQ(loop.stats().wake_latency.max_ns(), 0);
  EXPECT_EQ(loop.stats().ticks, r.ticks);
}

TEST(ControlLoop, TracksTargetsBeforeTheRamp) {
  FakeBackend daq;
  daq.configure();
  daq.activate();
  SimulatedClock clock;
  // Stop at 0.3 s through a "signal" raised by the plant, and check the stage before the ramp.
  std::atomic<int> stop{0};
  LoopConfig cfg = config(1000.0, 10.0);
  cfg.stop_signal = &stop;
  daq.signal_flag = &stop;
  daq.signal_tick = 299;
  Vec3 stage_at_stop{};
  daq.on_tick_at = 299;
  daq.on_tick_context = &stage_at_stop;
  static FakeBackend* plant = &daq;
  daq.on_tick = [](void* ctx) { *static_cast<Vec3*>(ctx) = plant->stage_um(); };
  ControlLoop loop(cfg, control::SemiClosedLoopParams{}, SafetyLimits{}, daq, clock,
                   SetpointProfile::step(8.0));
  const LoopResult r = loop.run();
  EXPECT_EQ(r.stop_reason, StopReason::kSignal);
  EXPECT_EQ(r.signal, 15);
  const Vec3 s = loop.controller().actuator_targets(Vec3{8.0, 8.0, 8.0});
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_NEAR(stage_at_stop[i], s[i], 1e-3) << "channel " << i;
  // The ramp after the stop request runs at the safe slew: 0.5 V per 1 ms tick.
  EXPECT_GT(r.ticks, 300U);
  EXPECT_EQ(loop.supervisor().state(), SupervisorState::kStopped);
}

TEST(ControlLoop, ControllerRunsAtTheLoopsRealSampleTime) {
  FakeBackend daq;
  SimulatedClock clock;
  ControlLoop loop(config(10'000.0, 0.01), control::SemiClosedLoopParams{}, SafetyLimits{}, daq,
                   clock, SetpointProfile::step(1.0));
  EXPECT_EQ(loop.period_ns(), 100'000);
  EXPECT_EQ(loop.duration_ticks(), 100U);
  EXPECT_DOUBLE_EQ(loop.controller().params().sample_time_s, 1e-4);
  // gains tuned at 1 ms, re-expressed at 0.1 ms: ki x 0.1, kd x 10, kp unchanged
  EXPECT_NEAR(loop.controller().channel(0).params().gains.ki, 0.02, 1e-15);
  EXPECT_NEAR(loop.controller().channel(0).params().gains.kd, 0.01, 1e-15);
  EXPECT_DOUBLE_EQ(loop.controller().channel(0).params().gains.kp, 0.6);
}

TEST(ControlLoop, RunMakesNoHeapAllocation) {
  FakeBackend daq;
  daq.configure();
  daq.activate();
  SimulatedClock clock;
  SpscRing<TelemetryRecord> ring(1 << 10);
  ControlLoop loop(config(10'000.0, 0.2), control::SemiClosedLoopParams{}, SafetyLimits{}, daq,
                   clock, SetpointProfile::step(5.0), &ring);
  testing::AllocationCounter counter;
  const LoopResult r = loop.run();
  EXPECT_EQ(counter.stop(), 0);
  EXPECT_GT(r.ticks, 2000U);
  EXPECT_EQ(r.telemetry_dropped, r.ticks - 1024U) << "a full ring drops, never blocks";
  TelemetryRecord first{};
  ASSERT_TRUE(ring.try_pop(first));
  EXPECT_EQ(first.tick, 0U);
}

TEST(ControlLoop, OverrunBurstLatchesAfterThreeConsecutive) {
  FakeBackend daq;
  SimulatedClock clock;
  const std::int64_t period = 1'000'000;
  FaultInjectingBackend faulty(daq, clock, period, {FaultSpec{FaultKind::kOverrunBurst, 0.1, -1}},
                               FaultInjectionParams{}, &daq);
  faulty.configure();
  faulty.activate();
  ControlLoop loop(config(1000.0, 0.3), control::SemiClosedLoopParams{}, SafetyLimits{}, faulty,
                   clock, SetpointProfile::step(3.0));
  const LoopResult r = loop.run();
  ASSERT_TRUE(r.fault_detected);
  EXPECT_EQ(r.fault.reason, FaultReason::kOverruns);
  EXPECT_EQ(faulty.injected_tick(0), 100U);
  EXPECT_EQ(r.fault.tick - faulty.injected_tick(0), 3U);
  EXPECT_EQ(r.stop_reason, StopReason::kFault);
  EXPECT_EQ(loop.stats().max_consecutive_overruns, 5U) << "the burst is 5 ticks of 1.5 periods";
  EXPECT_EQ(loop.stats().skipped_slots, 5U);
  EXPECT_LE(r.max_output_slew_V_per_ms, 1.5 + 1e-9);
}

TEST(ControlLoop, ExplicitClearResumesControl) {
  FakeBackend daq;
  SimulatedClock clock;
  FaultInjectingBackend faulty(daq, clock, 1'000'000, {FaultSpec{FaultKind::kAdcSpike, 0.1, 1}},
                               FaultInjectionParams{}, &daq);
  faulty.configure();
  faulty.activate();
  LoopConfig cfg = config(1000.0, 0.6);
  cfg.stop_when_safe_after_fault = false;  // wait for the operator
  ControlLoop loop(cfg, control::SemiClosedLoopParams{}, SafetyLimits{}, faulty, clock,
                   SetpointProfile::step(6.0));
  daq.on_tick_at = 250;  // the "operator" clears at 0.25 s
  daq.on_tick_context = &loop;
  daq.on_tick = [](void* ctx) { static_cast<ControlLoop*>(ctx)->request_clear(); };
  const LoopResult r = loop.run();
  ASSERT_TRUE(r.fault_detected);
  EXPECT_EQ(r.fault.reason, FaultReason::kSgsJump);
  EXPECT_EQ(r.fault.tick, 100U);
  EXPECT_EQ(r.fault.channel, 1);
  EXPECT_EQ(r.stop_reason, StopReason::kDuration) << "cleared, then ran to the end";
  EXPECT_EQ(loop.supervisor().state(), SupervisorState::kStopped);
  EXPECT_FALSE(loop.supervisor().faulted());
  EXPECT_LE(r.max_output_slew_V_per_ms, 1.5 + 1e-9);
}

// Every latch is kept, a cleared fault and the next one are two entries, each with its
// scheduled time, and each is published to the status for the host's reporter.
TEST(ControlLoop, EveryLatchedFaultIsKeptAndPublished) {
  FakeBackend daq;
  SimulatedClock clock;
  FaultInjectingBackend faulty(
      daq, clock, 1'000'000,
      {FaultSpec{FaultKind::kAdcSpike, 0.1, 1}, FaultSpec{FaultKind::kAdcNan, 0.4, 2}},
      FaultInjectionParams{}, &daq);
  faulty.configure();
  faulty.activate();
  LoopStatus status;
  LoopConfig cfg = config(1000.0, 0.6);
  cfg.stop_when_safe_after_fault = false;
  cfg.status = &status;
  ControlLoop loop(cfg, control::SemiClosedLoopParams{}, SafetyLimits{}, faulty, clock,
                   SetpointProfile::step(6.0));
  daq.on_tick_at = 250;  // the "operator" clears the first at 0.25 s
  daq.on_tick_context = &loop;
  daq.on_tick = [](void* ctx) { static_cast<ControlLoop*>(ctx)->request_clear(); };
  const LoopResult r = loop.run();
  ASSERT_EQ(r.faults.count, 2U);
  EXPECT_EQ(r.faults.entries[0].fault.reason, FaultReason::kSgsJump);
  EXPECT_EQ(r.faults.entries[0].fault.tick, 100U);
  EXPECT_EQ(r.faults.entries[0].fault.channel, 1);
  EXPECT_DOUBLE_EQ(r.faults.entries[0].t_s, 0.1);
  EXPECT_EQ(r.faults.entries[1].fault.reason, FaultReason::kSgsNotFinite);
  EXPECT_EQ(r.faults.entries[1].fault.tick, 400U);
  EXPECT_EQ(r.faults.entries[1].fault.channel, 2);
  EXPECT_DOUBLE_EQ(r.faults.entries[1].t_s, 0.4);
  EXPECT_EQ(status.faults_published.load(), 2U);
  EXPECT_EQ(status.faults[1].fault.tick, 400U);
  EXPECT_EQ(r.fault.tick, 400U) << "LoopResult::fault: the one latched at the end";
}

// An overrun trip carries the worst lateness of its overruns. The burst's ticks take
// 1.5 periods each: 0.5 ms past the next deadline, and each skips a slot, so the latch at tick
// 103 is scheduled at 106 ms.
TEST(ControlLoop, AnOverrunTripCarriesItsWorstLateness) {
  FakeBackend daq;
  SimulatedClock clock;
  FaultInjectingBackend faulty(daq, clock, 1'000'000,
                               {FaultSpec{FaultKind::kOverrunBurst, 0.1, -1}},
                               FaultInjectionParams{}, &daq);
  faulty.configure();
  faulty.activate();
  ControlLoop loop(config(1000.0, 0.3), control::SemiClosedLoopParams{}, SafetyLimits{}, faulty,
                   clock, SetpointProfile::step(3.0));
  const LoopResult r = loop.run();
  ASSERT_EQ(r.faults.count, 1U);
  const LatchedFault& f = r.faults.entries[0];
  EXPECT_EQ(f.fault.reason, FaultReason::kOverruns);
  EXPECT_EQ(f.fault.tick, 103U);
  EXPECT_DOUBLE_EQ(f.t_s, 0.106);
  EXPECT_DOUBLE_EQ(f.worst_lateness_s, 0.5e-3);
}

TEST(FaultList, KeepsTheFirstSixteenAndCountsEveryOne) {
  FaultList list;
  for (std::uint64_t k = 0; k < 20; ++k) {
    LatchedFault f;
    f.fault.tick = k;
    list.append(f);
  }
  EXPECT_EQ(list.count, 20U);
  EXPECT_EQ(list.kept(), 16U);
  EXPECT_EQ(list.entries[15].fault.tick, 15U);
}

TEST(ControlLoop, DaqReadErrorLatches) {
  FakeBackend daq;
  daq.configure();
  daq.activate();
  daq.fail_reads = true;
  SimulatedClock clock;
  ControlLoop loop(config(1000.0, 0.1), control::SemiClosedLoopParams{}, SafetyLimits{}, daq, clock,
                   SetpointProfile::step(3.0));
  const LoopResult r = loop.run();
  EXPECT_EQ(r.fault.reason, FaultReason::kDaqRead);
  EXPECT_EQ(r.fault.tick, 0U);
  EXPECT_EQ(r.max_output_V, 0.0) << "nothing ever left 0 V";
}

}  // namespace
}  // namespace piezoshift::runtime
