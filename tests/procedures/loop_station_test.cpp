// The loop station on the twin, its loop paced by the station (a runtime::PacedClock): a move, a
// wait on target, the data recorder, an injected fault by its name, the ramp to 0 V at close,
// and the refusals.
#include <cmath>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/procedures/loop_station.hpp"
#include "station_fixture.hpp"

namespace piezoshift::procedures {
namespace {

using control::Vec3;

using testing::twin_options;

// Expects `call` to throw E whose message contains `text`.
template <typename E, typename F>
void expect_refusal(F call, const std::string& text) {
  try {
    call();
    ADD_FAILURE() << "no exception; expected one saying: " << text;
  } catch (const E& e) {
    EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
  }
}

TEST(LoopStation, MovesWaitsOnTargetAndRecordsTheStep) {
  LoopStation s(twin_options(true));
  EXPECT_EQ(s.daq_name(), "sim");
  testing::expect_move_wait_record(s);
}

TEST(LoopStation, AnInjectedFaultRaisesByItsName) {
  LoopStationOptions o = twin_options(true);
  o.faults = {"sgs-open@0.3:2"};  // the gauge bridge of channel 2 opens at 0.3 s
  LoopStation s(o);
  s.servo(true);
  s.move({4.0, 0.0, 0.0});
  s.wait_on_target(10.0);  // well before the fault
  // Half a second of the loop: the recorder reads through the fault, which does not stop it.
  s.record(500, 1, {RecorderSignal::kPosition});
  EXPECT_EQ(s.read_recording(10.0).time_s.size(), 500u);
  try {
    s.move({6.0, 0.0, 0.0});
    ADD_FAILURE() << "no fault";
  } catch (const StationFaulted& e) {
    EXPECT_EQ(e.fault().name, "sgs-rail");
    EXPECT_EQ(e.fault().channel, 2);
    EXPECT_GE(e.fault().t_s, 0.3 - 1e-9);
    EXPECT_NE(std::string(e.what()).find("sgs-rail on channel 2"), std::string::npos) << e.what();
  }
  ASSERT_TRUE(s.fault().has_value());
  EXPECT_FALSE(s.servo_on());
  expect_refusal<StationFaulted>([&] { s.wait_on_target(1.0); }, "sgs-rail");
  // The gauge stays open: servo on clears the latch, which latches again at once.
  expect_refusal<StationFaulted>([&] { s.servo(true); }, "sgs-rail");
  s.close();
  EXPECT_EQ(s.output_V(), (Vec3{0.0, 0.0, 0.0}));
}

TEST(LoopStation, CloseRampsTheOutputsToZeroOnce) {
  LoopStation s(twin_options(true));
  s.servo(true);
  s.move({8.0, 0.0, 0.0});
  s.wait_on_target(10.0);
  s.update();
  EXPECT_GT(s.output_V()[0], 0.5);
  s.close();
  EXPECT_TRUE(s.closed());
  EXPECT_EQ(s.output_V(), (Vec3{0.0, 0.0, 0.0}));
  s.close();  // idempotent
  expect_refusal<std::logic_error>([&] { s.move({1.0, 0.0, 0.0}); }, "the stage is closed");
}

TEST(LoopStation, WaitOnTargetTimesOutNamingTheBand) {
  LoopStationOptions o = twin_options(true);
  o.on_target_um = 1e-9;  // below the gauges' noise: never on target
  LoopStation s(o);
  s.servo(true);
  s.move({3.0, 0.0, 0.0});
  expect_refusal<StationTimeout>([&] { s.wait_on_target(0.05); }, "not on target after 0.05 s");
  EXPECT_FALSE(s.on_target());
}

TEST(LoopStation, ServoOffHoldsTheVoltsAndRefusesMoves) {
  LoopStation s(twin_options(true));
  expect_refusal<std::logic_error>([&] { s.move({1.0, 0.0, 0.0}); }, "the servo is off");
  s.servo(true);
  s.move({6.0, 0.0, 0.0});
  s.wait_on_target(10.0);
  s.update();
  const Vec3 held = s.output_V();
  s.servo(false);
  s.update();
  EXPECT_FALSE(s.servo_on());
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_NEAR(s.output_V()[i], held[i], 0.05) << i;
  expect_refusal<std::logic_error>([&] { s.wait_on_target(1.0); }, "the servo is off");
}

TEST(LoopStation, RefusesWhatTheLoopCannotDo) {
  LoopStation s(twin_options(true));
  s.servo(true);
  expect_refusal<core::InputError>([&] { s.move({50.0, 0.0, 0.0}); }, "out of reach");
  expect_refusal<core::InputError>([&] { s.move({NAN, 0.0, 0.0}); }, "not a number");
  expect_refusal<std::logic_error>([&] { s.read_recording(1.0); }, "nothing recorded");
  expect_refusal<core::InputError>([&] { s.record(0, 1, {}); }, "recorder samples 0");
  LoopStationOptions o = twin_options(false);
  o.rate_Hz = 50.0;
  expect_refusal<core::InputError>([&] { LoopStation bad(o); }, "--rate-hz");
  o = twin_options(false);
  o.faults = {"sgs-open@x"};
  expect_refusal<core::InputError>([&] { LoopStation bad(o); }, "sgs-open@x");
  o = twin_options(false);
  o.daq = "comedi:/dev/comedi9";
  o.free_run = true;
  expect_refusal<core::InputError>([&] { LoopStation bad(o); }, "free_run");
  o = twin_options(false);
  o.settle_s = 11.0;
  expect_refusal<core::InputError>([&] { LoopStation bad(o); }, "settle_s 11");
}

}  // namespace
}  // namespace piezoshift::procedures
