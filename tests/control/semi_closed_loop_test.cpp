#include "piezoshift/control/semi_closed_loop.hpp"

#include <algorithm>

#include <gtest/gtest.h>

namespace piezoshift::control {
namespace {

TEST(SemiClosedLoop, FeedforwardIsMatrixTimesPolynomial) {
  const SemiClosedLoopController c;  // paper defaults
  // p(5) = 5.3585125, p(7) = 7.2911..., p(9) = 9.2470...; S = A [p(5), p(7), p(9)]
  const Vec3 s = c.actuator_targets(Vec3{5.0, 7.0, 9.0});
  EXPECT_NEAR(s[0], 8.32425590803, 1e-9);
  EXPECT_NEAR(s[1], 7.29351336355, 1e-9);
  EXPECT_NEAR(s[2], 3.83554344336, 1e-9);
}

TEST(SemiClosedLoop, FirstTickScalesPidOutputToDacVolts) {
  SemiClosedLoopParams params;
  params.polynomial = CubicPolynomial::identity();
  params.matrix = TransmissionMatrix::identity();
  SemiClosedLoopController c(params);
  // sgs 1 V -> 1.6 um; e = 4 - 1.6 = 2.4; u = 0.801 * 2.4 (from rest) = 1.9224 um -> x 0.625 V/um
  const ControllerOutput out = c.update(Vec3{4.0, 4.0, 4.0}, Vec3{1.0, 1.0, 1.0});
  EXPECT_NEAR(out.feedback_um[0], 1.6, 1e-15);
  EXPECT_NEAR(out.command_um[2], 1.9224, 1e-12);
  EXPECT_NEAR(out.dac_V[1], 1.9224 * 0.625, 1e-12);
  EXPECT_EQ(out.saturated_mask, 0);
}

// A static plant where each stack delivers 91 % of its nominal stroke (Eq. 1 with k_m = 6.78 N/um)
// and the sensor reads it exactly: the inner loops must drive the SGS readings to S = A p(Z_d).
TEST(SemiClosedLoop, InnerLoopsTrackActuatorTargetsOnStaticPlant) {
  SemiClosedLoopController c;
  const Vec3 zd{6.0, 6.0, 6.0};
  Vec3 sgs{};
  for (int k = 0; k < 400; ++k) {
    const ControllerOutput out = c.update(zd, sgs);
    for (std::size_t i = 0; i < 3; ++i)
      sgs[i] = 0.91 * (out.dac_V[i] / 0.625) / 1.6;
  }
  const Vec3 s = c.actuator_targets(zd);
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_NEAR(sgs[i] * 1.6, s[i], 1e-9);
}

TEST(SemiClosedLoop, TargetBeyondStrokeSaturatesAtTenVolts) {
  SemiClosedLoopParams params;
  params.matrix = TransmissionMatrix::identity();
  SemiClosedLoopController c(params);
  ControllerOutput out{};
  for (int k = 0; k < 100; ++k)
    out = c.update_actuators(Vec3{20.0, 0.0, 0.0}, Vec3{});
  EXPECT_DOUBLE_EQ(out.dac_V[0], 10.0);
  EXPECT_EQ(out.saturated_mask, 0b001);
  EXPECT_EQ(c.channel(0).state().saturated_count, 100U);
}

TEST(SemiClosedLoop, SampleTimeRescalesTheGains) {
  SemiClosedLoopParams params;
  params.sample_time_s = 1e-4;
  SemiClosedLoopController c(params);
  EXPECT_NEAR(c.channel(0).params().gains.ki, 0.02, 1e-15);
  EXPECT_NEAR(c.channel(0).params().gains.kd, 0.01, 1e-15);
}

// The float instantiation (the firmware's, docs/mcu.md) is the same algorithm: on the static
// plant it tracks the same targets, to float precision (2^-24 relative, ~1e-6 um at 8 um).
TEST(SemiClosedLoop, FloatInstantiationTracksLikeTheDoubleOne) {
  SemiClosedLoopController c;
  BasicSemiClosedLoopController<float> f(convert<float>(SemiClosedLoopParams{}));
  const Vec3 zd{6.0, 7.0, 8.0};
  Vec3 sgs{};
  BasicVec3<float> sgs_f{};
  double max_diff_um = 0.0;
  for (int k = 0; k < 400; ++k) {
    const ControllerOutput out = c.update(zd, sgs);
    const auto out_f = f.update(convert<float>(zd), sgs_f);
    for (std::size_t i = 0; i < 3; ++i) {
      sgs[i] = 0.91 * (out.dac_V[i] / 0.625) / 1.6;
      sgs_f[i] = 0.91F * (out_f.dac_V[i] / 0.625F) / 1.6F;
      const double d = out.command_um[i] - double{out_f.command_um[i]};
      max_diff_um = std::max(max_diff_um, d < 0.0 ? -d : d);
    }
  }
  EXPECT_LT(max_diff_um, 1e-5);
  const Vec3 s = c.actuator_targets(zd);
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_NEAR(double{sgs_f[i]} * 1.6, s[i], 1e-5);
}

}  // namespace
}  // namespace piezoshift::control
