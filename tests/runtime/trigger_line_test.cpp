// The loop's trigger pulse (control_loop.hpp) on the fake's and the twin's trigger lines.
#include <cstdint>

#include <gtest/gtest.h>

#include "fake_backend.hpp"
#include "piezoshift/runtime/control_loop.hpp"
#include "piezoshift/runtime/sim_backend.hpp"

#include "allocation_counter.hpp"

namespace piezoshift::runtime {
namespace {

using testing::FakeBackend;

constexpr std::int64_t kPeriodNs = 1'000'000;

LoopConfig owner_config() {
  LoopConfig c;
  c.rate_Hz = 1000.0;
  c.duration_s = 10.0;
  c.owner_drives = true;
  return c;
}

struct LineRig {
  FakeBackend daq;
  SimulatedClock clock;
  SpscRing<TelemetryRecord> ring{1 << 10};
  ControlLoop loop;

  LineRig()
      : loop(owner_config(), control::SemiClosedLoopParams{}, SafetyLimits{}, prepare(daq), clock,
             SetpointProfile::step(0.0), &ring) {
    loop.start();
  }
  static FakeBackend& prepare(FakeBackend& d) {
    d.trigger_line = true;
    d.configure();
    d.activate();
    return d;
  }
  void ticks(int n) {
    for (int k = 0; k < n; ++k)
      ASSERT_TRUE(loop.tick());
  }
};

TEST(TriggerLine, EachArmGivesExactlyWidthHighTicksFromTheNextTick) {
  for (std::uint32_t width : {1U, 3U, 7U}) {
    LineRig rig;
    rig.ticks(10);
    ASSERT_TRUE(rig.loop.arm_trigger_pulse(width));
    EXPECT_EQ(rig.daq.high_ticks, 0) << "armed, not yet raised";
    rig.ticks(30);
    EXPECT_EQ(rig.daq.high_ticks, static_cast<int>(width)) << "width " << width;
    EXPECT_EQ(rig.daq.rising_edges, 1);
    EXPECT_EQ(rig.daq.rising_ticks[0], 10U) << "the tick after the arm raises it";
    EXPECT_FALSE(rig.daq.line_high());
    EXPECT_EQ(rig.loop.trigger_pulses(), 1U);
    EXPECT_EQ(rig.loop.last_trigger_edge().tick, 10U);
    // Staged on the rising and the falling tick only: the ticks between pay nothing.
    EXPECT_EQ(rig.daq.line_stages, 2);
  }
}

TEST(TriggerLine, NoPulseAndNoStagingWhenNotArmed) {
  LineRig rig;
  rig.ticks(500);
  EXPECT_EQ(rig.daq.line_stages, 0);
  EXPECT_EQ(rig.daq.high_ticks, 0);
  EXPECT_EQ(rig.loop.trigger_pulses(), 0U);
  EXPECT_FALSE(rig.loop.trigger_line_high());
}

TEST(TriggerLine, ArmWhileArmedOrHighIsRefusedNotQueued) {
  LineRig rig;
  rig.ticks(2);
  ASSERT_TRUE(rig.loop.arm_trigger_pulse(4));
  EXPECT_FALSE(rig.loop.arm_trigger_pulse(4)) << "already armed";
  rig.ticks(1);
  EXPECT_TRUE(rig.loop.trigger_line_high());
  EXPECT_FALSE(rig.loop.arm_trigger_pulse(1)) << "high";
  rig.ticks(3);
  EXPECT_FALSE(rig.loop.arm_trigger_pulse(1)) << "the falling tick has not run yet";
  rig.ticks(1);
  EXPECT_FALSE(rig.loop.trigger_line_high());
  EXPECT_TRUE(rig.loop.arm_trigger_pulse(1));
  rig.ticks(5);
  EXPECT_EQ(rig.daq.rising_edges, 2) << "the refused arms queued nothing";
  EXPECT_EQ(rig.daq.high_ticks, 5);
  EXPECT_EQ(rig.daq.rising_ticks[1], 7U);
}

TEST(TriggerLine, WidthOutOfRangeOrNoLineIsRefused) {
  LineRig rig;
  EXPECT_FALSE(rig.loop.arm_trigger_pulse(0));
  EXPECT_FALSE(rig.loop.arm_trigger_pulse(ControlLoop::kMaxTriggerPulseTicks + 1));
  EXPECT_TRUE(rig.loop.arm_trigger_pulse(ControlLoop::kMaxTriggerPulseTicks));

  FakeBackend plain;  // no trigger line
  plain.configure();
  plain.activate();
  SimulatedClock clock;
  ControlLoop loop(owner_config(), control::SemiClosedLoopParams{}, SafetyLimits{}, plain, clock,
                   SetpointProfile::step(0.0));
  loop.start();
  EXPECT_FALSE(loop.arm_trigger_pulse(1));
  ASSERT_TRUE(loop.tick());
  EXPECT_EQ(plain.line_stages, 0);
}

// A tick that overruns makes the loop skip slots: the edge's time is its tick's scheduled time
// (as the telemetry reports it), not tick x period.
TEST(TriggerLine, EdgeTimeIsTheRaisingTicksScheduledTime) {
  LineRig rig;
  static SimulatedClock* clock = &rig.clock;
  rig.daq.on_tick_at = 4;
  rig.daq.on_tick = [](void*) { clock->stall_ns(2 * kPeriodNs + kPeriodNs / 2); };
  rig.ticks(6);
  ASSERT_GT(rig.loop.stats().skipped_slots, 0U);
  ASSERT_TRUE(rig.loop.arm_trigger_pulse(2));
  rig.ticks(3);
  const TriggerEdge& edge = rig.loop.last_trigger_edge();
  EXPECT_EQ(edge.tick, 6U);
  EXPECT_NE(edge.since_start_ns, 6 * kPeriodNs);
  TelemetryRecord r{};
  bool found = false;
  while (rig.ring.try_pop(r))
    if (r.tick == edge.tick) {
      found = true;
      EXPECT_EQ(edge.since_start_ns, std::llround(r.t_s * 1e9));
    }
  EXPECT_TRUE(found);
  EXPECT_EQ(edge.since_start_ns % kPeriodNs, 0) << "on a tick boundary";
}

TEST(TriggerLine, PulsesMakeNoHeapAllocation) {
  LineRig rig;
  testing::AllocationCounter counter;
  for (int k = 0; k < 100; ++k) {
    rig.loop.arm_trigger_pulse(3);
    rig.ticks(5);
  }
  EXPECT_EQ(counter.stop(), 0);
  EXPECT_EQ(rig.daq.rising_edges, 100);
  EXPECT_EQ(rig.daq.high_ticks, 300);
}

TEST(TriggerLine, StartLowersALinePulseCutShort) {
  LineRig rig;
  ASSERT_TRUE(rig.loop.arm_trigger_pulse(50));
  rig.ticks(3);
  ASSERT_TRUE(rig.loop.trigger_line_high());
  rig.loop.start();
  EXPECT_FALSE(rig.loop.trigger_line_high());
  EXPECT_EQ(rig.loop.trigger_pulses(), 0U);
  rig.ticks(1);
  EXPECT_FALSE(rig.daq.line_high());
}

// The twin's line: each rising edge recorded on its wire with the tick and its scheduled time,
// for the owner thread to take in order.
TEST(TriggerLine, SimBackendRecordsItsRisingEdgesOnTheWire) {
  SimBackend sim(SimOptions{});
  sim.configure();
  sim.activate();
  EXPECT_TRUE(sim.has_trigger_line());
  SimulatedClock clock;
  ControlLoop loop(owner_config(), control::SemiClosedLoopParams{}, SafetyLimits{}, sim, clock,
                   SetpointProfile::step(0.0));
  loop.start();
  for (int k = 0; k < 5; ++k)
    ASSERT_TRUE(loop.tick());
  ASSERT_TRUE(loop.arm_trigger_pulse(2));
  ASSERT_TRUE(loop.tick());
  EXPECT_TRUE(sim.trigger_line_high());
  for (int k = 0; k < 10; ++k)
    ASSERT_TRUE(loop.tick());
  EXPECT_FALSE(sim.trigger_line_high());
  ASSERT_TRUE(loop.arm_trigger_pulse(1));
  for (int k = 0; k < 3; ++k)
    ASSERT_TRUE(loop.tick());
  EXPECT_EQ(sim.trigger_edges(), 2U);
  TriggerEdge e{};
  ASSERT_TRUE(sim.take_trigger_edge(e));
  EXPECT_EQ(e.tick, 5U);
  EXPECT_EQ(e.since_start_ns, 5 * kPeriodNs);
  ASSERT_TRUE(sim.take_trigger_edge(e));
  EXPECT_EQ(e.tick, 16U);
  EXPECT_EQ(e.since_start_ns, 16 * kPeriodNs);
  EXPECT_FALSE(sim.take_trigger_edge(e));
  EXPECT_EQ(sim.trigger_edges_dropped(), 0U);
}

TEST(TriggerLine, SimWireKeepsTheFirstEdgesAndCountsTheRestWhenFull) {
  SimBackend sim(SimOptions{});
  sim.configure();
  sim.activate();
  SimulatedClock clock;
  ControlLoop loop(owner_config(), control::SemiClosedLoopParams{}, SafetyLimits{}, sim, clock,
                   SetpointProfile::step(0.0));
  loop.start();
  const std::size_t n = SimBackend::kWireEdges + 6;
  for (std::size_t k = 0; k < n; ++k) {
    ASSERT_TRUE(loop.arm_trigger_pulse(1));
    ASSERT_TRUE(loop.tick());
    ASSERT_TRUE(loop.tick());
  }
  EXPECT_EQ(sim.trigger_edges(), n);
  EXPECT_EQ(sim.trigger_edges_dropped(), 6U);
  TriggerEdge e{};
  ASSERT_TRUE(sim.take_trigger_edge(e));
  EXPECT_EQ(e.tick, 0U);
}

}  // namespace
}  // namespace piezoshift::runtime
