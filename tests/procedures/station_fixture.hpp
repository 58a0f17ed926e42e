#pragma once
// A loop station on the twin, servo on, for the station's tests.
#include <cmath>

#include <gtest/gtest.h>

#include "piezoshift/procedures/loop_station.hpp"

namespace piezoshift::procedures::testing {

inline LoopStationOptions twin_options(bool free_run) {
  LoopStationOptions o;
  o.daq = "sim-rt";
  o.free_run = free_run;
  o.request_realtime = false;  // a test process is no place for mlockall
  return o;
}

// A step of Z to 5 um (mid-travel), recorded from the tick after record(); the failure guards
// are generous: the paper's step settles in tens of milliseconds.
inline void expect_move_wait_record(LoopStation& s) {
  s.servo(true);
  ASSERT_TRUE(s.servo_on());
  const host::AxisValues before = s.target();  // where servo on closed the loop
  s.record(400, 2, {RecorderSignal::kTarget, RecorderSignal::kPosition, RecorderSignal::kOutputV});
  s.move({5.0, 0.0, 0.0});
  s.wait_on_target(10.0);
  EXPECT_TRUE(s.on_target());
  const host::AxisValues p = s.position();
  EXPECT_NEAR(p[0], 5.0, 0.01);  // serve's default band, 10 nm
  EXPECT_NEAR(p[1], 0.0, 0.5);
  EXPECT_NEAR(p[2], 0.0, 0.5);
  const Recording& r = s.read_recording(10.0);
  ASSERT_EQ(r.time_s.size(), 400u);
  EXPECT_EQ(r.ticks_missed, 0u);
  EXPECT_TRUE(r.of(RecorderSignal::kInterferometer).empty());  // not asked for
  const auto& target = r.of(RecorderSignal::kTarget);
  const auto& position = r.of(RecorderSignal::kPosition);
  ASSERT_EQ(target.size(), 400u);
  ASSERT_EQ(position.size(), 400u);
  // Every other tick: two periods apart, or whole periods more where a late tick (the real-time
  // clock on a busy machine) skipped slots.
  for (std::size_t i = 1; i < r.time_s.size(); ++i) {
    const double periods = (r.time_s[i] - r.time_s[i - 1]) * s.rate_Hz();
    ASSERT_GE(periods, 2.0 - 1e-6) << i;
    ASSERT_NEAR(periods, std::round(periods), 1e-6) << i;
  }
  EXPECT_DOUBLE_EQ(target.front()[0], before[0]);  // before the move
  EXPECT_DOUBLE_EQ(target.back()[0], 5.0);
  EXPECT_LT(position.front()[0], 1.0);
  EXPECT_NEAR(position.back()[0], 5.0, 0.02);
  EXPECT_GT(r.of(RecorderSignal::kOutputV).back()[0], 1.0);  // the amplifier drives the stack
}

}  // namespace piezoshift::procedures::testing
