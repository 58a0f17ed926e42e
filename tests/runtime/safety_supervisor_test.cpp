#include "piezoshift/runtime/safety_supervisor.hpp"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace piezoshift::runtime {
namespace {

constexpr double kT = 1e-3;
// g = G / (0.625 V/um * 1.6 um/V) = 0.9117; jump bound = 0.05 + 2.5 * 1500 V/s * T * g
constexpr double kJump1kHz = 0.05 + 2.5 * 1500.0 * 1e-3 * 0.9117;   // 3.468875 V
constexpr double kJump10kHz = 0.05 + 2.5 * 1500.0 * 1e-4 * 0.9117;  // 0.3918875 V

SafetySupervisor make(double sample_time_s = kT) {
  SafetySupervisor s;
  s.configure(SafetyLimits{}, sample_time_s, {});
  return s;
}

// A consistent operating point: SGS reads what the applied output makes (G u), on target.
SupervisorInput steady(std::uint64_t tick, double ao_V) {
  SupervisorInput in;
  in.tick = tick;
  in.period_s = kT;
  const double y_um = 0.9117 * ao_V / 0.625;
  in.sgs_V = control::filled(y_um / 1.6);
  in.feedback_um = control::filled(y_um);
  in.target_um = in.feedback_um;
  in.request_V = control::filled(ao_V);
  return in;
}

TEST(SafetySupervisor, JumpBoundMatchesHandCalculation) {
  EXPECT_NEAR(make().jump_limit_V(0, 1e-3), kJump1kHz, 1e-12);
  EXPECT_NEAR(make(1e-4).jump_limit_V(2, 1e-4), kJump10kHz, 1e-12);
}

TEST(SafetySupervisor, SlewLimitsRisingOutputTo1500VPerS) {
  SafetySupervisor s = make();
  SupervisorInput in = steady(0, 0.0);
  in.request_V = control::filled(5.0);
  const double expected[] = {1.5, 3.0, 4.5, 5.0, 5.0};
  for (std::uint64_t k = 0; k < 5; ++k) {
    in.tick = k;
    const SupervisorOutput out = s.update(in);
    EXPECT_NEAR(out.ao_V[1], expected[k], 1e-12) << "tick " << k;
    EXPECT_EQ(out.limited, k < 3) << "tick " << k;
    EXPECT_EQ(out.hold_integrators, k < 3) << "conditional integration while limited";
  }
  EXPECT_FALSE(s.faulted());
}

TEST(SafetySupervisor, SlewStepScalesWithSampleTime) {
  SafetySupervisor s = make(1e-4);
  SupervisorInput in = steady(0, 0.0);
  in.period_s = 1e-4;
  in.request_V = control::filled(5.0);
  EXPECT_NEAR(s.update(in).ao_V[0], 0.15, 1e-12);
  // a long tick (skipped slots) does not buy a larger step
  in.tick = 1;
  in.period_s = 5e-4;
  EXPECT_NEAR(s.update(in).ao_V[0], 0.30, 1e-12);
}

TEST(SafetySupervisor, OutputsNeverLeaveZeroToTenVolts) {
  SafetySupervisor s = make();
  SupervisorInput in = steady(0, 0.0);
  in.request_V = Vec3{12.0, -3.0, 1e9};
  double top = 0.0;
  for (std::uint64_t k = 0; k < 20; ++k) {
    in.tick = k;
    const SupervisorOutput out = s.update(in);
    EXPECT_EQ(out.ao_V[1], 0.0);
    top = std::max(top, std::max(out.ao_V[0], out.ao_V[2]));
  }
  EXPECT_EQ(top, 10.0);
  EXPECT_EQ(s.last_output_V()[0], 10.0);
}

TEST(SafetySupervisor, NanSgsLatchesAndRampsToZeroAtSafeSlew) {
  SafetySupervisor s = make();
  for (std::uint64_t k = 0; k < 10; ++k)
    s.update(steady(k, 2.0));
  ASSERT_NEAR(s.last_output_V()[0], 2.0, 1e-12);
  SupervisorInput in = steady(10, 2.0);
  in.sgs_V[2] = std::numeric_limits<double>::quiet_NaN();
  SupervisorOutput out = s.update(in);
  ASSERT_TRUE(s.faulted());
  EXPECT_EQ(s.fault().reason, FaultReason::kSgsNotFinite);
  EXPECT_EQ(s.fault().tick, 10U);
  EXPECT_EQ(s.fault().channel, 2);
  EXPECT_TRUE(out.hold_integrators);
  // 500 V/s * 1 ms = 0.5 V per tick: 1.5, 1.0, 0.5, 0.0, even though the controller asks for 2 V
  EXPECT_NEAR(out.ao_V[0], 1.5, 1e-12);
  for (const double v : {1.0, 0.5, 0.0}) {
    out = s.update(steady(11, 2.0));
    EXPECT_NEAR(out.ao_V[1], v, 1e-12);
  }
  EXPECT_TRUE(s.outputs_at_zero());
  EXPECT_EQ(out.state, SupervisorState::kFaulted);
}

TEST(SafetySupervisor, RailIsWithin20mVOfFullScale) {
  SafetySupervisor a = make();
  a.update(steady(0, 10.0));  // sgs = 9.117 V: the next reading stays inside the jump bound
  SupervisorInput in = steady(1, 10.0);
  in.sgs_V[0] = 9.97;
  in.feedback_um[0] = 9.97 * 1.6;
  in.target_um[0] = in.feedback_um[0];
  a.update(in);
  EXPECT_FALSE(a.faulted()) << "9.97 V is a legal (if implausible) reading";

  SafetySupervisor b = make();
  b.update(steady(0, 10.0));
  in.sgs_V[0] = 9.98;
  b.update(in);
  ASSERT_TRUE(b.faulted());
  EXPECT_EQ(b.fault().reason, FaultReason::kSgsRail);
  EXPECT_EQ(b.fault().channel, 0);
  SafetySupervisor c = make();
  in.sgs_V[0] = -10.0;
  c.update(in);
  EXPECT_EQ(c.fault().reason, FaultReason::kSgsRail);
}

TEST(SafetySupervisor, RangeIsTheConditionersZeroToTenVoltsWithMargin) {
  SafetySupervisor a = make();
  SupervisorInput in = steady(0, 0.0);
  in.sgs_V[1] = -0.24;
  a.update(in);
  EXPECT_FALSE(a.faulted());
  in.sgs_V[1] = -0.26;
  in.tick = 1;
  a.update(in);
  ASSERT_TRUE(a.faulted());
  EXPECT_EQ(a.fault().reason, FaultReason::kSgsRange);
  EXPECT_EQ(a.fault().channel, 1);
  EXPECT_EQ(a.fault().limit, -0.25);
}

TEST(SafetySupervisor, JumpLargerThanThePhysicsAllowsInOneTick) {
  for (const auto& [period, bound] : {std::pair{1e-3, kJump1kHz}, std::pair{1e-4, kJump10kHz}}) {
    SafetySupervisor ok = make(period);
    SafetySupervisor bad = make(period);
    SupervisorInput in = steady(0, 0.0);
    in.period_s = period;
    in.sgs_V = control::filled(5.0);
    ok.update(in);
    bad.update(in);
    in.tick = 1;
    in.sgs_V[2] = 5.0 + 0.999 * bound;
    ok.update(in);
    EXPECT_FALSE(ok.faulted()) << period;
    in.sgs_V[2] = 5.0 - 1.001 * bound;
    bad.update(in);
    ASSERT_TRUE(bad.faulted()) << period;
    EXPECT_EQ(bad.fault().reason, FaultReason::kSgsJump);
    EXPECT_EQ(bad.fault().tick, 1U);
    EXPECT_NEAR(bad.fault().value, -1.001 * bound, 1e-12);
  }
}

TEST(SafetySupervisor, TrackingErrorMustPersist100Ticks) {
  SafetySupervisor s = make();
  // y = 3.5 um, S = 5 um; the output that makes y consistent with G u: u = 3.5 / G um
  const double ao = 3.5 / 0.9117 * 0.625;
  SupervisorInput in = steady(0, ao);
  in.target_um = control::filled(5.0);
  for (std::uint64_t k = 0; k < 100; ++k) {
    in.tick = k;
    s.update(in);
    ASSERT_EQ(s.faulted(), k == 99) << "tick " << k;
  }
  EXPECT_EQ(s.fault().reason, FaultReason::kTracking);
  EXPECT_EQ(s.fault().tick, 99U);
  EXPECT_NEAR(s.fault().value, 1.5, 1e-9);
}

TEST(SafetySupervisor, StackNotAnsweringItsDriveMustPersist20Ticks) {
  // A dead amplifier: 5 V out, the SGS stays at 0, the controller's target is at 0 too (so the
  // tracking rule is quiet). The check at tick k uses the output of tick k-1: 1.5 V at tick 1 is
  // u = 2.4 um, whose window starts at 0.4 * 2.4 - 0.8 = 0.16 um > 0, so counting starts at tick 1
  // and trips at tick 20.
  SafetySupervisor s = make();
  SupervisorInput in = steady(0, 0.0);
  in.request_V = control::filled(5.0);
  for (std::uint64_t k = 0; k <= 20; ++k) {
    in.tick = k;
    s.update(in);
    ASSERT_EQ(s.faulted(), k == 20) << "tick " << k;
  }
  EXPECT_EQ(s.fault().reason, FaultReason::kResponse);
  EXPECT_EQ(s.fault().channel, 0);
  EXPECT_NEAR(s.fault().limit, 0.4 * 8.0 - 0.8, 1e-12);  // u = 5 V / 0.625 V/um, b = 0.8 um
}

TEST(SafetySupervisor, ResponseWindowSpansHysteresis) {
  // 0.46 and 0.9 um per um (the twin's hysteresis extremes) stay quiet for 1000 ticks; 1.4 trips.
  for (const double gain : {0.46, 0.9, 1.4}) {
    SafetySupervisor s = make();
    for (std::uint64_t k = 0; k < 1000 && !s.faulted(); ++k) {
      SupervisorInput in = steady(k, 6.0);
      const double u = s.last_output_V()[0] / 0.625;  // the stage follows the ramp up
      in.feedback_um = control::filled(gain * u);
      in.sgs_V = control::filled(gain * u / 1.6);
      in.target_um = in.feedback_um;
      s.update(in);
    }
    EXPECT_EQ(s.faulted(), gain > 1.3) << gain;
    if (s.faulted()) {
      EXPECT_EQ(s.fault().reason, FaultReason::kResponse);
      EXPECT_NEAR(s.fault().limit, 1.3 * 9.6 + 0.8, 1e-9);
    }
  }
}

TEST(SafetySupervisor, OutputPinnedAtItsLimitFor50msLatches) {
  SafetySupervisor s = make();
  // The controller asks for more than 10 V; the stage answers (in the window), the target is out
  // of reach but the tracking rule needs 100 ticks: saturation (50 ticks at 10 V) comes first.
  // The output reaches 10 V at tick 6 (1.5 V per tick), counted from the check of tick 7.
  for (std::uint64_t k = 0; k < 100 && !s.faulted(); ++k) {
    SupervisorInput in = steady(k, 10.0);
    in.request_V = control::filled(12.0);
    in.target_um = control::filled(14.0);
    const double u = s.last_output_V()[0] / 0.625;
    in.feedback_um = control::filled(0.9117 * u);
    in.sgs_V = control::filled(0.9117 * u / 1.6);
    s.update(in);
  }
  ASSERT_TRUE(s.faulted());
  EXPECT_EQ(s.fault().reason, FaultReason::kSaturation);
  EXPECT_EQ(s.fault().tick, 7U + 49U);
}

TEST(SafetySupervisor, ThreeConsecutiveOverrunsLatch) {
  SafetySupervisor s = make();
  SupervisorInput in = steady(0, 0.0);
  const bool overran[] = {true, true, false, true, true, true};
  for (std::uint64_t k = 0; k < 6; ++k) {
    in.tick = k;
    in.previous_tick_overran = overran[k];
    s.update(in);
    ASSERT_EQ(s.faulted(), k == 5) << "tick " << k;
  }
  EXPECT_EQ(s.fault().reason, FaultReason::kOverruns);
  EXPECT_EQ(s.fault().value, 3.0);
}

// With trip_on_overruns never (the twin's default in run and serve) a late host is
// counted, not a fault; "on hardware" is "always" to the supervisor.
TEST(SafetySupervisor, OverrunsTripOnlyWhereTheLimitsAskForIt) {
  for (const std::uint32_t mode : {kOverrunTripNever, kOverrunTripAlways, kOverrunTripOnHardware}) {
    SafetyLimits limits;
    limits.trip_on_overruns = mode;
    SafetySupervisor s;
    s.configure(limits, kT, {});
    SupervisorInput in = steady(0, 0.0);
    for (std::uint64_t k = 0; k < 10; ++k) {
      in.tick = k;
      in.previous_tick_overran = true;
      s.update(in);
    }
    EXPECT_EQ(s.faulted(), mode != kOverrunTripNever) << "mode " << mode;
    if (mode != kOverrunTripNever) {
      EXPECT_EQ(s.fault().reason, FaultReason::kOverruns);
      EXPECT_EQ(s.fault().tick, 2U) << "the third overrun in a row";
    }
  }
}

TEST(SafetySupervisor, DaqErrorsLatch) {
  SafetySupervisor a = make();
  SupervisorInput in = steady(0, 0.0);
  in.read_status = DaqStatus::kError;
  a.update(in);
  EXPECT_EQ(a.fault().reason, FaultReason::kDaqRead);
  SafetySupervisor b = make();
  in.read_status = DaqStatus::kOk;
  in.previous_write_status = DaqStatus::kClamped;
  b.update(in);
  EXPECT_FALSE(b.faulted()) << "a clamped write is reported, not a fault";
  in.previous_write_status = DaqStatus::kError;
  b.update(in);
  EXPECT_EQ(b.fault().reason, FaultReason::kDaqWrite);
}

TEST(SafetySupervisor, NonFiniteControllerOutputLatchesAndRamps) {
  SafetySupervisor s = make();
  s.update(steady(0, 1.0));
  SupervisorInput in = steady(1, 1.0);
  in.request_V[1] = std::numeric_limits<double>::infinity();
  const SupervisorOutput out = s.update(in);
  EXPECT_EQ(s.fault().reason, FaultReason::kOutputNotFinite);
  EXPECT_NEAR(out.ao_V[1], 0.5, 1e-12);
}

TEST(SafetySupervisor, FaultStaysLatchedUntilExplicitClear) {
  SafetySupervisor s = make();
  SupervisorInput in = steady(0, 0.0);
  in.sgs_V[0] = -1.0;
  s.update(in);
  ASSERT_EQ(s.fault().reason, FaultReason::kSgsRange);
  // Inputs healthy again, a second different problem: the first fault stays, outputs stay at 0.
  for (std::uint64_t k = 1; k < 50; ++k) {
    SupervisorInput good = steady(k, 4.0);
    good.read_status = k == 5 ? DaqStatus::kError : DaqStatus::kOk;
    const SupervisorOutput out = s.update(good);
    EXPECT_EQ(out.ao_V[0], 0.0);
    EXPECT_TRUE(out.hold_integrators);
  }
  EXPECT_EQ(s.fault().reason, FaultReason::kSgsRange);
  EXPECT_EQ(s.fault().tick, 0U);

  ASSERT_TRUE(s.clear_fault());
  EXPECT_FALSE(s.clear_fault()) << "nothing left to clear";
  EXPECT_EQ(s.state(), SupervisorState::kRunning);
  const SupervisorOutput out = s.update(steady(50, 4.0));
  EXPECT_NEAR(out.ao_V[0], 1.5, 1e-12) << "resumes through the slew limit";
  EXPECT_FALSE(s.faulted());
}

TEST(SafetySupervisor, StopRampsToZeroThenStops) {
  SafetySupervisor s = make();
  for (std::uint64_t k = 0; k < 5; ++k)
    s.update(steady(k, 1.2));
  s.request_stop();
  EXPECT_EQ(s.state(), SupervisorState::kStopping);
  SupervisorOutput out = s.update(steady(5, 1.2));
  EXPECT_NEAR(out.ao_V[0], 0.7, 1e-12);
  EXPECT_TRUE(out.hold_integrators);
  out = s.update(steady(6, 1.2));
  EXPECT_NEAR(out.ao_V[0], 0.2, 1e-12);
  out = s.update(steady(7, 1.2));
  EXPECT_EQ(out.ao_V[0], 0.0);
  EXPECT_EQ(out.state, SupervisorState::kStopped);
  EXPECT_FALSE(s.faulted());
}

TEST(SafetySupervisor, RejectsInconsistentLimits) {
  SafetySupervisor s;
  SafetyLimits bad;
  bad.safe_ramp_V_per_s = 2.0 * bad.max_slew_V_per_s;
  EXPECT_THROW(s.configure(bad, kT, {}), std::invalid_argument);
  SafetyLimits no_zero;
  no_zero.output_min_V = 1.0;
  EXPECT_THROW(s.configure(no_zero, kT, {}), std::invalid_argument);
}

TEST(SafetySupervisor, OpenLoopHasNoTrackingOrSaturationRule) {
  // The saturation case above, and a tracking error of 4 um, with the servo off (`serve`'s SVA):
  // 10 V held for 100 ticks is an operator's choice, not lost authority; there is no target.
  SafetySupervisor s = make();
  for (std::uint64_t k = 0; k < 150; ++k) {
    SupervisorInput in = steady(k, 10.0);
    in.closed_loop = false;
    in.target_um = control::filled(14.0);
    const double u = s.last_output_V()[0] / 0.625;
    in.feedback_um = control::filled(0.9117 * u);
    in.sgs_V = control::filled(0.9117 * u / 1.6);
    s.update(in);
  }
  EXPECT_FALSE(s.faulted()) << to_string(s.fault().reason);
  EXPECT_EQ(s.last_output_V()[0], 10.0);
  // The response rule still holds in open loop: a dead amplifier trips it at the same tick as in
  // StackNotAnsweringItsDriveMustPersist20Ticks.
  SafetySupervisor dead = make();
  SupervisorInput in = steady(0, 0.0);
  in.closed_loop = false;
  in.request_V = control::filled(5.0);
  for (std::uint64_t k = 0; k <= 20; ++k) {
    in.tick = k;
    dead.update(in);
    ASSERT_EQ(dead.faulted(), k == 20) << "tick " << k;
  }
  EXPECT_EQ(dead.fault().reason, FaultReason::kResponse);
}

// The oscillation rule's counter on made-up errors: a reversal is a swing of the band back from
// the last extreme; eight within the window, with the target steady, trip it.
TEST(ReversalCounter, EightReversalsOfASteadyTargetWithinTheWindowTrip) {
  ReversalCounter c;
  // A square wave of +-0.3 um about 0 (swings of 0.6 um >= the 0.5 um band), 2 ticks per level:
  // the first swing sets the direction, each later one is a reversal.
  std::uint64_t tripped_at = 0;
  for (std::uint64_t k = 0; k < 100 && tripped_at == 0; ++k) {
    const double e = (k / 2) % 2 == 0 ? 0.3 : -0.3;
    if (c.update(k, e, 5.0, 0.5, 8, 100))
      tripped_at = k;
  }
  // Levels change at ticks 2, 4, 6, ...: the change at 2 sets the direction, 4 .. 18 are
  // reversals 1 .. 8.
  EXPECT_EQ(tripped_at, 18U);
}

TEST(ReversalCounter, SwingsBelowTheBandOrSpreadBeyondTheWindowDoNotTrip) {
  ReversalCounter small, slow;
  for (std::uint64_t k = 0; k < 1000; ++k) {
    ASSERT_FALSE(small.update(k, (k / 2) % 2 == 0 ? 0.2 : -0.2, 5.0, 0.5, 8, 100)) << k;
    // 0.6 um swings every 20 ticks: 8 reversals span 140 ticks > 100.
    ASSERT_FALSE(slow.update(k, (k / 20) % 2 == 0 ? 0.3 : -0.3, 5.0, 0.5, 8, 100)) << k;
  }
}

TEST(ReversalCounter, AMovingTargetIsACommandedMotionNotAnOscillation) {
  ReversalCounter c;
  // The same error, but the target jumps by 1 um at each level (a wave the loop lags).
  for (std::uint64_t k = 0; k < 1000; ++k) {
    const bool high = (k / 2) % 2 == 0;
    ASSERT_FALSE(c.update(k, high ? 0.3 : -0.3, high ? 5.0 : 6.0, 0.5, 8, 100)) << k;
  }
}

TEST(SafetySupervisor, AnOscillatingTrackingErrorLatchesOscillation) {
  SafetySupervisor s = make();
  const double ao = 3.5 / 0.9117 * 0.625;
  SupervisorInput in = steady(0, ao);
  std::uint64_t k = 0;
  for (; k < 200 && !s.faulted(); ++k) {
    in.tick = k;
    // y swings +-0.4 um about S every 2 ticks (the limit cycle kp 5, ki 3, kd 2 ran in
    // swung 2.4 um at 250 Hz); |S - y| stays below the tracking rule's 1 um.
    const double y = 3.5 + ((k / 2) % 2 == 0 ? 0.4 : -0.4);
    in.feedback_um = control::filled(y);
    in.target_um = control::filled(3.5);
    s.update(in);
  }
  ASSERT_TRUE(s.faulted());
  EXPECT_EQ(s.fault().reason, FaultReason::kOscillation);
  EXPECT_EQ(s.fault().tick, 18U);  // as the counter's test: the eighth reversal
  EXPECT_STREQ(to_string(s.fault().reason), "oscillation");
}

}  // namespace
}  // namespace piezoshift::runtime
