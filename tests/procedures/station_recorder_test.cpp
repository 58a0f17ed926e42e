// The loop station's recorder: its signals by name, the points it keeps and the ticks a stalled
// host link dropped.
#include <gtest/gtest.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/procedures/station_recorder.hpp"

namespace piezoshift::procedures {
namespace {

host::RecorderInput input(double z) {
  host::RecorderInput in{};
  in.target = {z, 0.0, 0.0};
  in.position = {z + 0.5, 1.0, 2.0};
  return in;
}

TEST(StationRecorder, NamesItsSignals) {
  EXPECT_EQ(parse_recorder_signal("output_V"), RecorderSignal::kOutputV);
  EXPECT_STREQ(to_string(RecorderSignal::kSensorUm), "sensor_um");
  try {
    parse_recorder_signal("voltage");
    ADD_FAILURE();
  } catch (const core::InputError& e) {
    EXPECT_STREQ(e.what(),
                 "recorder signal 'voltage': not one of target, position, interferometer, "
                 "output_V, sensor_um");
  }
}

TEST(StationRecorder, KeepsEveryNthTickFromItsFirst) {
  StationRecorder r;
  r.start(3, 2, {RecorderSignal::kPosition}, 10);
  for (std::uint64_t t = 8; t < 20; ++t)
    r.take(t, static_cast<double>(t) * 1e-3, input(static_cast<double>(t)));
  ASSERT_TRUE(r.complete());
  const Recording& rec = r.recording();
  ASSERT_EQ(rec.time_s.size(), 3u);
  EXPECT_DOUBLE_EQ(rec.time_s[0], 0.010);
  EXPECT_DOUBLE_EQ(rec.time_s[2], 0.014);
  EXPECT_DOUBLE_EQ(rec.of(RecorderSignal::kPosition)[1][0], 12.5);
  EXPECT_TRUE(rec.of(RecorderSignal::kTarget).empty());
}

TEST(StationRecorder, CountsDroppedTicksAndKeepsItsCadence) {
  StationRecorder r;
  r.start(3, 2, {}, 0);
  r.take(0, 0.0, input(0.0));
  r.take(5, 0.005, input(5.0));  // ticks 1..4 dropped; 5 is not due
  r.take(6, 0.006, input(6.0));
  r.take(7, 0.007, input(7.0));
  r.take(8, 0.008, input(8.0));
  ASSERT_TRUE(r.complete());
  EXPECT_EQ(r.recording().ticks_missed, 3u);  // ticks 2, 3 and 4 were due or between
  EXPECT_DOUBLE_EQ(r.recording().time_s[1], 0.006);
  EXPECT_EQ(r.recording().signals.size(), kRecorderSignals);
}

TEST(StationRecorder, RefusesBadArguments) {
  StationRecorder r;
  EXPECT_THROW(r.start(StationRecorder::kMaxPoints + 1, 1, {}, 0), core::InputError);
  EXPECT_THROW(r.start(10, 0, {}, 0), core::InputError);
  try {
    r.start(10, 1, {RecorderSignal::kTarget, RecorderSignal::kTarget}, 0);
    ADD_FAILURE();
  } catch (const core::InputError& e) {
    EXPECT_STREQ(e.what(), "recorder signal 'target': named twice");
  }
}

}  // namespace
}  // namespace piezoshift::procedures
