#include <cmath>
#include <complex>
#include <numbers>

#include <gtest/gtest.h>

#include "piezoshift/control/hysteresis_creep_model.hpp"
#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/control/setpoint_shaper.hpp"

namespace piezoshift::control {
namespace {

HysteresisCreepParams example_model() {
  HysteresisCreepParams p;
  p.offset_um = 0.01;
  p.linear_weight = 0.5;
  p.operators = 4;
  p.threshold_um = {1.0, 3.0, 5.0, 7.0};
  p.weight = {0.05, 0.0, 0.08, 0.1};
  p.creep_terms = 3;
  p.creep_time_constant_s = {0.01, 0.1, 1.0};
  p.creep_gain = 0.006;
  return p;
}

// The inverse is exact: the command it returns, committed, makes the model read the target, on
// a path with reversals at every scale (breakpoints crossed both ways) and creep running.
TEST(HysteresisCreepModel, InverseThenCommitReadsTheTarget) {
  HysteresisCreepModel m;
  m.configure(example_model(), 1e-3);
  const double targets[] = {3.0, 6.5, 2.0, 2.05, 5.0, 4.9, 7.9, 0.3, 7.5, 7.45, 7.46, 1.0};
  for (const double y : targets) {
    for (int k = 0; k < 5; ++k) {  // held a few ticks: creep moves the command, not the reading
      bool clamped = true;
      const double u = m.inverse(y, 0.0, 16.0, clamped);
      EXPECT_FALSE(clamped);
      m.commit(u);
      EXPECT_NEAR(m.output(), y, 1e-12) << "target " << y;
    }
  }
}

// Rising from rest along a major branch, the slope is w0 plus every operator passed: 0.5 below
// 1 um, 0.55 between 1 and 3 (the zero weight adds nothing), 0.63 above 5; right after a
// reversal only w0 remains.
TEST(HysteresisCreepModel, SlopesFollowTheOperatorsPassed) {
  HysteresisCreepParams p = example_model();
  p.creep_terms = 0;
  HysteresisCreepModel m;
  m.configure(p, 1e-3);
  m.commit(0.5);
  EXPECT_NEAR(m.slope(true), 0.5, 1e-15);
  m.commit(2.0);
  EXPECT_NEAR(m.slope(true), 0.55, 1e-15);
  m.commit(6.0);
  EXPECT_NEAR(m.slope(true), 0.63, 1e-15);
  EXPECT_NEAR(m.slope(false), 0.5, 1e-15);
  // y on the rising branch: 0.01 + 0.5 u + 0.05 (u - 1) + 0.08 (u - 5) at u = 6.
  EXPECT_NEAR(m.output(), 0.01 + 3.0 + 0.25 + 0.08, 1e-12);
}

TEST(HysteresisCreepModel, OutOfReachTargetsAreClampedAndSaySo) {
  HysteresisCreepModel m;
  m.configure(example_model(), 1e-3);
  bool clamped = false;
  EXPECT_EQ(m.inverse(100.0, 0.0, 16.0, clamped), 16.0);
  EXPECT_TRUE(clamped);
  EXPECT_EQ(m.inverse(-1.0, 0.0, 16.0, clamped), 0.0);
  EXPECT_TRUE(clamped);
}

std::complex<double> shaper_response(const ShaperParams& p, double theta) {
  std::complex<double> h = 0.0;
  for (std::size_t i = 0; i < p.taps; ++i)
    h += p.weight[i] * std::polar(1.0, -theta * static_cast<double>(i));
  return h;
}

// At 1 kHz the paper's 1419 Hz piston mode folds to 419 Hz: three positive taps with a zero
// there; at 10 kHz a mode at 1/(7 T) gets a 7-tap moving average, whose first zero it is.
TEST(SetpointShaper, TapsNullTheModeAndKeepUnitGain) {
  const double two_pi = 2.0 * std::numbers::pi;
  const ShaperParams a = design_mode_shaper(1419.0, 1e-3, 1e9);
  ASSERT_EQ(a.taps, 3U);
  EXPECT_NEAR(a.weight[0] + a.weight[1] + a.weight[2], 1.0, 1e-15);
  EXPECT_GT(a.weight[0], 0.0);
  EXPECT_GT(a.weight[1], 0.0);
  EXPECT_LT(std::abs(shaper_response(a, two_pi * 1419.0 * 1e-3)), 1e-12);
  const ShaperParams b = design_mode_shaper(10000.0 / 7.0, 1e-4, 1e9);
  ASSERT_EQ(b.taps, 7U);
  EXPECT_LT(std::abs(shaper_response(b, two_pi / 7.0)), 1e-12);
  EXPECT_EQ(design_mode_shaper(0.0, 1e-3, 1e9).taps, 1U);
}

// The rate limit: a 10 um step at 1000 um/s and 1 ms moves at most 1 um per tick, then the taps
// spread it; it arrives exactly.
TEST(SetpointShaper, StepIsRateLimitedThenArrives) {
  SetpointShaper s;
  ShaperParams p = design_mode_shaper(1419.0, 1e-3, 1000.0);
  s.configure(p, 1e-3);
  double previous = 0.0;
  for (int k = 0; k < 14; ++k) {
    const double r = s.update(10.0);
    EXPECT_LE(r - previous, 1.0 + 1e-12);
    previous = r;
  }
  EXPECT_NEAR(previous, 10.0, 1e-12);
}

// The improved controller on example_model() in every channel, identity p and A, the paper's
// plate mode shaped at 1 kHz, 2 ticks of delay: the loop the closed-loop tests below run.
SemiClosedLoopParams model_loop_params() {
  SemiClosedLoopParams params;
  params.kind = ControllerKind::kImproved;
  params.polynomial = CubicPolynomial::identity();
  params.matrix = TransmissionMatrix::identity();
  for (auto& m : params.improved.model)
    m = example_model();
  params.improved.shaper = design_mode_shaper(1419.0, 1e-3, 1000.0);
  params.improved.reference_delay_ticks = 2;
  params.improved.correction_ki = 0.05;
  return params;
}

// Closed on a plant that is the model itself (y = model(u), D = 2 ticks late, plus a 20 nm
// bias): the improved controller reaches the target and its correction takes the bias.
TEST(ImprovedController, TracksAPlantThatIsItsModelWithABias) {
  SemiClosedLoopParams params = model_loop_params();
  SemiClosedLoopController c(params);
  HysteresisCreepModel plant;
  plant.configure(example_model(), 1e-3);
  double y1 = plant.output(), y2 = y1;
  ControllerOutput out{};
  for (int k = 0; k < 400; ++k) {
    const double y = y2 + 0.02;  // what the gauges read: two ticks late, 20 nm off
    out = c.update(Vec3{4.0, 4.0, 4.0}, filled(y / 1.6));
    plant.commit(out.command_um[0]);
    y2 = y1;
    y1 = plant.output();
  }
  EXPECT_NEAR(y1 + 0.02, 4.0, 1e-6);
  EXPECT_EQ(out.saturated_mask, 0);
}

// A large move (docs/control.md, "Large moves"): the command steps by the slew limit each tick, the
// reference follows what the model reads (so the correction does not wind up on the move), the slew
// stops slew_approach_um before the target and the shaper makes the rest; a small move never slews.
TEST(ImprovedController, LargeMoveSlewsThenTheShaperFinishes) {
  SemiClosedLoopParams params = model_loop_params();
  params.improved.command_slew_um_per_s = 2000.0;  // 2 um of command per tick
  params.improved.slew_approach_um = 1.0;
  SemiClosedLoopController c(params);
  HysteresisCreepModel plant;
  plant.configure(example_model(), 1e-3);
  double y1 = plant.output(), y2 = y1, previous = 0.0;
  int full_steps = 0;
  ControllerOutput out{};
  for (int k = 0; k < 400; ++k) {
    out = c.update(Vec3{10.0, 10.0, 10.0}, filled(y2 / 1.6));
    const double du = out.command_um[0] - previous;
    EXPECT_LE(du, 2.0 + 1e-9);
    full_steps += du > 2.0 - 1e-9 ? 1 : 0;
    if (k < full_steps) {  // while slewing: the model's reading, the target at least 1 um away
      EXPECT_LE(c.model(0).output(), 10.0 - 1.0 + 1e-9);
    }
    previous = out.command_um[0];
    plant.commit(out.command_um[0]);
    y2 = y1;
    y1 = plant.output();
  }
  EXPECT_GE(full_steps, 3);
  EXPECT_NEAR(y1, 10.0, 1e-6);
  // A move of less than twice the approach is the shaper's alone: its rate limit, 1 um a tick.
  previous = c.model(0).output();
  for (int k = 0; k < 20; ++k) {
    out = c.update(Vec3{11.5, 11.5, 11.5}, filled(c.model(0).output() / 1.6));
    EXPECT_LE(c.model(0).output() - previous, 1.0 + 1e-9);
    previous = c.model(0).output();
  }
}

}  // namespace
}  // namespace piezoshift::control
