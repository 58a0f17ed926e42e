#include "piezoshift/control/incremental_pid.hpp"

#include <cmath>

#include <gtest/gtest.h>

namespace piezoshift::control {
namespace {

// Plant: y(k) = u(k-1), a unit gain with one sample of delay (ZOH + sampling).
// With the paper's gains (kp 0.6, ki 0.2, kd 0.001) and a unit step command, by hand:
//   k=0: e=1,        du = 0.6*1 + 0.2*1 + 0.001*1                      = 0.801,      u = 0.801
//   k=1: e=0.199,    du = 0.6*(-0.801) + 0.2*0.199 + 0.001*(0.199-2)   = -0.442601,  u = 0.358399
//   k=2: e=0.641601, du = 0.6*0.442601 + 0.2*0.641601 + 0.001*1.243601 = 0.395124401, u=0.753523401
TEST(IncrementalPid, MatchesHandComputedSequenceOnDelayedUnitPlant) {
  IncrementalPid pid(PidParams{PidGains{0.6, 0.2, 0.001}, -10.0, 10.0, 0.0, 0.0});
  double y = 0.0;
  const double expected[] = {0.801, 0.358399, 0.753523401};
  for (double u_expected : expected) {
    const double u = pid.update(1.0, y);
    EXPECT_NEAR(u, u_expected, 1e-12);
    y = u;
  }
}

TEST(IncrementalPid, ConvergesWithoutSteadyStateErrorOnStaticPlant) {
  IncrementalPid pid(PidParams{});
  double y = 0.0;
  for (int k = 0; k < 300; ++k)
    y = 0.91 * pid.update(12.0, y);
  EXPECT_NEAR(y, 12.0, 1e-9);
}

TEST(IncrementalPid, ClampedOutputIsCarriedForwardSoNoWindUp) {
  IncrementalPid pid(PidParams{PidGains{0.6, 0.2, 0.001}, 0.0, 0.5, 0.0, 0.0});
  EXPECT_DOUBLE_EQ(pid.update(1.0, 0.0), 0.5);  // raw 0.801
  EXPECT_TRUE(pid.state().saturated);
  EXPECT_EQ(pid.state().saturated_count, 1U);
  // Next increment starts from the clamped 0.5: du = 0.6*(0.5-1) + 0.2*0.5 + 0.001*(0.5-2)
  EXPECT_NEAR(pid.update(1.0, 0.5), 0.5 - 0.2015, 1e-12);
  EXPECT_FALSE(pid.state().saturated);
  EXPECT_EQ(pid.state().saturated_count, 0U);
  EXPECT_EQ(pid.state().saturated_total, 1U);
}

TEST(IncrementalPid, LowerLimitAndConsecutiveSaturationCount) {
  IncrementalPid pid(PidParams{PidGains{0.6, 0.2, 0.0}, 0.0, 16.0, 0.0, 0.0});
  for (int k = 0; k < 4; ++k)
    EXPECT_DOUBLE_EQ(pid.update(-3.0, 0.0), 0.0);
  EXPECT_EQ(pid.state().saturated_count, 4U);
}

TEST(IncrementalPid, DerivativeFilterWeightsTheSecondDifference) {
  IncrementalPid pid(PidParams{PidGains{0.6, 0.2, 0.001}, -10.0, 10.0, 0.0, 0.5});
  // d2 = 1, filtered 0.5 d2f + 0.5 d2 = 0.5: du = 0.6 + 0.2 + 0.0005
  EXPECT_NEAR(pid.update(1.0, 0.0), 0.8005, 1e-12);
}

TEST(IncrementalPid, DeadbandTreatsSmallErrorsAsZero) {
  IncrementalPid pid(PidParams{PidGains{0.6, 0.2, 0.0}, -10.0, 10.0, 0.01, 0.0});
  EXPECT_DOUBLE_EQ(pid.update(0.005, 0.0), 0.0);
  EXPECT_NEAR(pid.update(0.02, 0.0), 0.6 * 0.02 + 0.2 * 0.02, 1e-15);
}

TEST(IncrementalPid, ResetClearsHistoryAndStartsFromGivenOutput) {
  IncrementalPid pid(PidParams{});
  pid.update(5.0, 0.0);
  pid.update(5.0, 1.0);
  pid.reset(2.0);
  EXPECT_DOUBLE_EQ(pid.state().output, 2.0);
  EXPECT_DOUBLE_EQ(pid.state().error_1, 0.0);
  // From a clean history: du = 0.6*1 + 0.2*1 + 0.001*1
  EXPECT_NEAR(pid.update(1.0, 0.0), 2.801, 1e-12);
}

TEST(IncrementalPid, DisabledForcesZeroOutputAndClearsState) {
  IncrementalPid pid(PidParams{});
  pid.update(5.0, 0.0);
  pid.set_enabled(false);
  EXPECT_DOUBLE_EQ(pid.update(5.0, 0.0), 0.0);
  EXPECT_DOUBLE_EQ(pid.state().error_1, 0.0);
  pid.set_enabled(true);
  EXPECT_NEAR(pid.update(1.0, 0.0), 0.801, 1e-12);
}

TEST(IncrementalPid, HeldIntegratorDropsOnlyTheIntegralTerm) {
  IncrementalPid pid(PidParams{PidGains{0.6, 0.2, 0.0}, -10.0, 10.0, 0.0, 0.0});
  pid.hold_integrator(true);
  EXPECT_NEAR(pid.update(1.0, 0.0), 0.6, 1e-15);
  EXPECT_NEAR(pid.update(1.0, 0.0), 0.6, 1e-15);  // constant error, no integral: no change
}

TEST(IncrementalPid, NanFeedbackNeverReachesTheOutput) {
  IncrementalPid pid(PidParams{});
  pid.update(1.0, 0.0);
  const double u = pid.update(1.0, std::nan(""));
  EXPECT_TRUE(std::isfinite(u));
}

TEST(PidGains, RescaleKeepsTheContinuousControllerUnchanged) {
  const PidGains g = rescale_gains(PidGains{0.6, 0.2, 0.001}, 1e-3, 1e-4);
  EXPECT_DOUBLE_EQ(g.kp, 0.6);
  EXPECT_NEAR(g.ki, 0.02, 1e-15);
  EXPECT_NEAR(g.kd, 0.01, 1e-15);
}

}  // namespace
}  // namespace piezoshift::control
