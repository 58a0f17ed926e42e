// The loop station as Python's Stage(daq="sim-rt") runs it: the twin on the monotonic clock, the
// loop on its own thread in real time. Only generous failure guards depend on time.
#include <gtest/gtest.h>

#include "piezoshift/procedures/loop_station.hpp"
#include "station_fixture.hpp"

namespace piezoshift::procedures {
namespace {

using control::Vec3;

TEST(LoopStationRealTime, MovesWaitsOnTargetRecordsAndRampsAtClose) {
  LoopStation s(testing::twin_options(false));
  testing::expect_move_wait_record(s);
  s.close();
  EXPECT_EQ(s.output_V(), (Vec3{0.0, 0.0, 0.0}));
}

}  // namespace
}  // namespace piezoshift::procedures
