// StageModel with the paper's controller (p, A, 1.6 um/V gauges) and the twin's geometry (actuator
// 1 on +y, then 210 and 330 deg; P1..P3 from A): Eq. 5 both ways, the inverted feedforward, the
// reachable set and the TMN/TMX limits, the open-loop mixing, and the constructor's refusals.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/host/stage_model.hpp"
#include "piezoshift/plant/geometry.hpp"
#include "piezoshift/runtime/controller_ranges.hpp"

namespace piezoshift::host {
namespace {

// The paper's p and A, 1.6 um/V gauges, the twin's geometry.
StageModelParams twin_params() {
  return stage_model_params(plant::GeometryParams{});
}

// SGS volts the loop settles at for a pose: y = S = A p(Z_d) (Eq. 8), volts = y / 1.6 um/V. The
// feedforward is the controller's own, not the model's.
Vec3 sgs_V_for(const StageModel& m, const AxisValues& pose) {
  const control::SemiClosedLoopController c(m.params().controller);
  const Vec3 s = c.actuator_targets(m.points_for(pose));
  return Vec3{s[0] / 1.6, s[1] / 1.6, s[2] / 1.6};
}

// The smallest margin of all the reachability constraints (header): points in [0, z_max] and
// actuator targets in [0, S_i(z_max)]; 0 on the boundary, negative outside.
double margin_um(const StageModel& m, const AxisValues& pose) {
  const control::SemiClosedLoopController c(m.params().controller);
  const double z_max = m.params().z_max_um;
  const Vec3 z = m.points_for(pose);
  const Vec3 s = c.actuator_targets(z);
  const Vec3 s_max = c.actuator_targets(control::filled(z_max));
  double margin = 1e300;
  for (std::size_t i = 0; i < 3; ++i) {
    margin = std::min({margin, z[i], z_max - z[i], s[i], s_max[i] - s[i]});
  }
  return margin;
}

TEST(StageModelTest, AxisNamesAndUnits) {
  EXPECT_STREQ(axis_name(Axis::kZ), "Z");
  EXPECT_STREQ(axis_name(Axis::kU), "U");
  EXPECT_STREQ(axis_name(Axis::kV), "V");
  EXPECT_STREQ(axis_unit(Axis::kZ), "um");
  EXPECT_STREQ(axis_unit(Axis::kU), "urad");
  EXPECT_STREQ(axis_unit(Axis::kV), "urad");
}

TEST(StageModelTest, PointsForIsEq5AtTheTwinsMeasurementPoints) {
  const StageModel m(twin_params());
  const AxisValues pose{4.2, 35.0, -20.0};
  const Vec3 z = m.points_for(pose);
  const auto& pts = m.params().measurement_points;
  for (std::size_t j = 0; j < 3; ++j) {
    // z = Z + theta_x y - theta_y x; urad * m = um.
    EXPECT_NEAR(z[j], 4.2 + 35.0 * pts[j].y_m + 20.0 * pts[j].x_m, 1e-12) << "P" << j + 1;
  }
}

TEST(StageModelTest, PointsAndPoseRoundTrip) {
  const StageModel m(twin_params());
  for (const AxisValues& pose : {AxisValues{0.0, 0.0, 0.0}, AxisValues{5.75, 40.0, -30.0},
                                 AxisValues{11.5, -12.5, 7.25}, AxisValues{-3.0, 1e3, 2e3}}) {
    const AxisValues back = m.pose_from_points(m.points_for(pose));
    for (std::size_t a = 0; a < 3; ++a)
      EXPECT_NEAR(back[a], pose[a], 1e-9) << "axis " << a;
  }
  const Vec3 z{1.0, 2.5, 7.0};
  const Vec3 again = m.points_for(m.pose_from_points(z));
  for (std::size_t j = 0; j < 3; ++j)
    EXPECT_NEAR(again[j], z[j], 1e-9);
}

TEST(StageModelTest, PurePistonMovesEveryPointEqually) {
  const StageModel m(twin_params());
  const Vec3 z = m.points_for({4.0, 0.0, 0.0});
  for (double zj : z)
    EXPECT_NEAR(zj, 4.0, 1e-12);
  const AxisValues pose = m.pose_from_points({7.0, 7.0, 7.0});
  EXPECT_NEAR(pose[0], 7.0, 1e-12);
  EXPECT_NEAR(pose[1], 0.0, 1e-9);
  EXPECT_NEAR(pose[2], 0.0, 1e-9);
}

TEST(StageModelTest, PoseFromSgsInvertsTheFeedforward) {
  const StageModel m(twin_params());
  for (const AxisValues& pose :
       {AxisValues{0.0, 0.0, 0.0}, AxisValues{5.75, 0.0, 0.0}, AxisValues{6.0, 25.0, -15.0},
        AxisValues{11.5, 0.0, 0.0}, AxisValues{3.0, -10.0, 20.0}}) {
    const AxisValues est = m.pose_from_sgs(sgs_V_for(m, pose));
    EXPECT_NEAR(est[0], pose[0], 1e-9);
    EXPECT_NEAR(est[1], pose[1], 1e-9);
    EXPECT_NEAR(est[2], pose[2], 1e-9);
  }
}

TEST(StageModelTest, PoseFromSgsAtZeroVoltsIsBelowZeroPiston) {
  // y = 0 -> Z_S = 0 -> every Z_i = p^-1(0) < 0 since p(0) = p0 = 0.2914 um > 0; a pure piston.
  const StageModel m(twin_params());
  const AxisValues est = m.pose_from_sgs(Vec3{});
  const control::CubicPolynomial p{};
  EXPECT_LT(est[0], 0.0);
  EXPECT_NEAR(p(est[0]), 0.0, 1e-10);
  // p(x) ~ p0 + p1 x near 0: x ~ -0.2914 / 1.014.
  EXPECT_NEAR(est[0], -0.2914 / 1.014, 1e-3);
  EXPECT_NEAR(est[1], 0.0, 1e-9);
  EXPECT_NEAR(est[2], 0.0, 1e-9);
}

TEST(StageModelTest, PoseFromSgsIsNanForANonFiniteGauge) {
  const StageModel m(twin_params());
  const AxisValues est = m.pose_from_sgs({1.0, std::nan(""), 1.0});
  for (double v : est)
    EXPECT_TRUE(std::isnan(v));
}

TEST(StageModelTest, ReachablePiston) {
  const StageModel m(twin_params());
  EXPECT_TRUE(m.reachable({0.0, 0.0, 0.0}));
  EXPECT_TRUE(m.reachable({11.5, 0.0, 0.0}));
  EXPECT_TRUE(m.reachable({5.75, 0.0, 0.0}));
  EXPECT_FALSE(m.reachable({11.6, 0.0, 0.0}));
  EXPECT_FALSE(m.reachable({-0.1, 0.0, 0.0}));
  EXPECT_FALSE(m.reachable({std::nan(""), 0.0, 0.0}));
  EXPECT_FALSE(m.reachable({5.0, std::numeric_limits<double>::infinity(), 0.0}));
}

TEST(StageModelTest, UnreachableReasonNamesThePointOrTheActuator) {
  const StageModel m(twin_params());
  EXPECT_EQ(m.unreachable_reason({5.0, 0.0, 0.0}), "");
  const std::string high = m.unreachable_reason({11.6, 0.0, 0.0});
  EXPECT_NE(high.find("P1"), std::string::npos) << high;
  EXPECT_NE(high.find("11.6000"), std::string::npos) << high;
  EXPECT_NE(high.find("11.5000"), std::string::npos) << high;

  // Points (11.5, 0, 0) are all in range, but A's negative first diagonal asks actuator 1 for
  // S_1 = -0.4218 p(11.5) + (0.6030 + 0.6547) p(0) = -0.4218 * 11.8504 + 1.2577 * 0.2914 = -4.632
  // um < 0.
  const AxisValues pose = m.pose_from_points({11.5, 0.0, 0.0});
  const std::string why = m.unreachable_reason(pose);
  EXPECT_NE(why.find("actuator 1"), std::string::npos) << why;
  const control::CubicPolynomial p{};
  const double s1 = -0.4218 * p(11.5) + (0.6030 + 0.6547) * p(0.0);
  EXPECT_NEAR(s1, -4.632, 0.001);
  char text[32];
  std::snprintf(text, sizeof text, "%.4f um", s1);
  EXPECT_NE(why.find(text), std::string::npos) << why;
}

TEST(StageModelTest, TravelLimits) {
  const StageModel m(twin_params());
  EXPECT_EQ(m.min_limits()[0], 0.0);
  EXPECT_EQ(m.max_limits()[0], 11.5);
  const double u_min = m.min_limits()[1];
  const double u_max = m.max_limits()[1];
  const double v_min = m.min_limits()[2];
  const double v_max = m.max_limits()[2];
  EXPECT_LT(u_min, 0.0);
  EXPECT_GT(u_max, 0.0);
  EXPECT_LT(v_min, 0.0);
  EXPECT_GT(v_max, 0.0);
  // At mid travel a tip U moves P_j by U y_j, so the points alone allow |U| <= 5.75 um / max|y_j|
  // and |V| <= 5.75 um / max|x_j|. With the paper's A the points, not the actuators, set the
  // limits, both ways. By hand from geometry.hpp's W and the 90/210/330 deg actuators at R = 50 mm:
  // P1 y = R (-0.3644 - (0.6974 + 0.6670) / 2) = -1.0466 R and P2 x = R sqrt(3)/2 (0.6724 + 0.4298)
  // = 0.9545 R are the largest, so U in +-5.75 / 0.05233 = +-109.88 urad and V in
  // +-5.75 / 0.04773 = +-120.48 urad.
  double y_max = 0.0;
  double x_max = 0.0;
  for (const auto& pt : m.params().measurement_points) {
    y_max = std::max(y_max, std::fabs(pt.y_m));
    x_max = std::max(x_max, std::fabs(pt.x_m));
  }
  EXPECT_NEAR(y_max, 1.0466 * 0.05, 1e-5);
  EXPECT_NEAR(x_max, 0.9545 * 0.05, 1e-5);
  EXPECT_NEAR(u_max, 5.75 / y_max, 1e-6);
  EXPECT_NEAR(u_min, -5.75 / y_max, 1e-6);
  EXPECT_NEAR(v_max, 5.75 / x_max, 1e-6);
  EXPECT_NEAR(v_min, -5.75 / x_max, 1e-6);
  EXPECT_NEAR(u_max, 109.88, 0.05);
  EXPECT_NEAR(v_max, 120.48, 0.1);

  // Each limit sits where a constraint becomes active, at mid travel with the other angle 0.
  const double z_mid = 5.75;
  for (std::size_t axis = 1; axis < 3; ++axis) {
    for (double limit : {m.min_limits()[axis], m.max_limits()[axis]}) {
      AxisValues at{z_mid, 0.0, 0.0};
      at[axis] = limit;
      EXPECT_NEAR(margin_um(m, at), 0.0, 1e-8) << "axis " << axis << " limit " << limit;
      const double sign = limit > 0 ? 1.0 : -1.0;
      AxisValues inside = at;
      inside[axis] = limit - sign * 1e-3;  // 1e-3 urad moves a point by ~5e-5 um >> 1e-9 um
      AxisValues outside = at;
      outside[axis] = limit + sign * 1e-3;
      EXPECT_TRUE(m.reachable(inside)) << "axis " << axis << " " << inside[axis];
      EXPECT_FALSE(m.reachable(outside)) << "axis " << axis << " " << outside[axis];
      EXPECT_GT(margin_um(m, inside), 0.0);
      EXPECT_LT(margin_um(m, outside), 0.0);
    }
  }
  // A move is checked as a whole pose: half the U limit is out of reach at Z = 0.
  EXPECT_FALSE(m.reachable({0.0, 0.5 * u_max, 0.0}));
  EXPECT_TRUE(m.reachable({z_mid, 0.5 * u_max, 0.0}));
}

TEST(StageModelTest, TravelFollowsZMax) {
  StageModelParams p = twin_params();
  p.z_max_um = 10.0;
  const StageModel m(p);
  EXPECT_EQ(m.min_limits()[0], 0.0);
  EXPECT_EQ(m.max_limits()[0], 10.0);
  EXPECT_TRUE(m.reachable({10.0, 0.0, 0.0}));
  EXPECT_FALSE(m.reachable({10.05, 0.0, 0.0}));
  // The angular limits are taken at the new mid travel, 5 um.
  AxisValues at{5.0, m.max_limits()[1], 0.0};
  EXPECT_NEAR(margin_um(m, at), 0.0, 1e-8);
  const StageModel full(twin_params());
  EXPECT_LT(m.max_limits()[1], full.max_limits()[1]);
}

TEST(StageModelTest, OpenLoopMixingFollowsTheActuatorLayout) {
  const StageModel m(twin_params());
  // Actuators at R (cos phi, sin phi), phi = 90, 210, 330 deg: y = R (1, -1/2, -1/2) and
  // x = R (0, -sqrt(3)/2, sqrt(3)/2). Tip column y_i / max|y| = (1, -1/2, -1/2); tilt column
  // -x_i / max|x| = (0, 1, -1).
  const Vec3 z = m.channel_V_for({30.0, 0.0, 0.0});
  for (double v : z)
    EXPECT_NEAR(v, 30.0, 1e-12);
  const Vec3 u = m.channel_V_for({0.0, 10.0, 0.0});
  EXPECT_NEAR(u[0], 10.0, 1e-12);
  EXPECT_NEAR(u[1], -5.0, 1e-12);
  EXPECT_NEAR(u[2], -5.0, 1e-12);
  const Vec3 v = m.channel_V_for({0.0, 0.0, 8.0});
  EXPECT_NEAR(v[0], 0.0, 1e-12);
  EXPECT_NEAR(v[1], 8.0, 1e-12);
  EXPECT_NEAR(v[2], -8.0, 1e-12);
  const Vec3 all = m.channel_V_for({30.0, 10.0, 8.0});
  EXPECT_NEAR(all[0], 40.0, 1e-12);
  EXPECT_NEAR(all[1], 33.0, 1e-12);
  EXPECT_NEAR(all[2], 17.0, 1e-12);

  const AxisValues back = m.open_loop_for({40.0, 33.0, 17.0});
  EXPECT_NEAR(back[0], 30.0, 1e-12);
  EXPECT_NEAR(back[1], 10.0, 1e-12);
  EXPECT_NEAR(back[2], 8.0, 1e-12);
  const AxisValues again = m.open_loop_for(m.channel_V_for({75.0, -12.5, 3.25}));
  EXPECT_NEAR(again[0], 75.0, 1e-12);
  EXPECT_NEAR(again[1], -12.5, 1e-12);
  EXPECT_NEAR(again[2], 3.25, 1e-12);
}

TEST(StageModelTest, ConstructorRefusesBadParameters) {
  EXPECT_NO_THROW(StageModel{twin_params()});

  StageModelParams singular = twin_params();
  singular.controller.matrix.a[2] = singular.controller.matrix.a[0];
  EXPECT_THROW(StageModel{singular}, std::invalid_argument);

  for (double z_max : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    StageModelParams p = twin_params();
    p.z_max_um = z_max;
    EXPECT_THROW(StageModel{p}, std::invalid_argument) << z_max;
  }

  StageModelParams decreasing = twin_params();
  decreasing.controller.polynomial = {0.0, 0.0, -1.0, 11.5};
  EXPECT_THROW(StageModel{decreasing}, std::invalid_argument);
  // Increasing at 0 but not on the whole inversion range [-z_max, 2 z_max]: p' = 3 p3 x^2 + ... is
  // 1 - 0.03 * 23^2 < 0 at 23 um.
  StageModelParams turning = twin_params();
  turning.controller.polynomial = {-0.01, 0.0, 1.0, 0.0};
  EXPECT_THROW(StageModel{turning}, std::invalid_argument);

  StageModelParams collinear = twin_params();
  collinear.measurement_points = {kinematics::PlatePoint{0.0, 0.0},
                                  kinematics::PlatePoint{0.01, 0.0},
                                  kinematics::PlatePoint{0.02, 0.0}};
  EXPECT_THROW(StageModel{collinear}, std::invalid_argument);

  StageModelParams no_gain = twin_params();
  no_gain.amplifier_gain = 0.0;
  EXPECT_THROW(StageModel{no_gain}, std::invalid_argument);
}

// Reproducer: with z_max_um = 1e308 POS? answered -nan. For every calibration the loader accepts
// (runtime/controller_ranges.hpp's bands, here at their corners) the gauges' whole +-10 V give a
// finite pose.
TEST(StageModelTest, PoseIsFiniteAtTheBandsCorners) {
  const control::SemiClosedLoopParams paper;
  const control::Mat3 matrices[] = {
      paper.matrix.a,
      {{{0.5, 0, 0}, {0, 0.5, 0}, {0, 0, 0.5}}},
      {{{1.5, 0, 0}, {0, 1.5, 0}, {0, 0, 1.5}}},
  };
  const control::CubicPolynomial cubics[] = {
      paper.polynomial,
      {0.0, 0.0, 0.5, 0.0},
      {0.0, 0.0, 2.0, 0.0},
      {-0.00048, 0.0, 1.5, 0.0},  // slope 1.13 at 16 um, 0.025 at 32 um
  };
  for (const control::Mat3& a : matrices)
    for (const control::CubicPolynomial& p : cubics)
      for (double z_max : {0.5, 11.1, runtime::kStrokeUm}) {
        StageModelParams params = twin_params();
        params.controller.matrix.a = a;
        params.controller.polynomial = p;
        params.z_max_um = z_max;
        ASSERT_EQ(runtime::controller_problem(params.controller, 1e-3), "");
        ASSERT_TRUE(runtime::travel_problem(z_max, std::nullopt).empty());
        const StageModel model(params);
        for (int corner = 0; corner < 27; ++corner) {
          const Vec3 v{-10.0 + 10.0 * (corner % 3), -10.0 + 10.0 * (corner / 3 % 3),
                       -10.0 + 10.0 * (corner / 9)};
          for (double x : model.pose_from_sgs(v))
            EXPECT_TRUE(std::isfinite(x)) << "p1 " << p.p1 << ", A[0][0] " << a[0][0] << ", z_max "
                                          << z_max << ", corner " << corner;
        }
      }
}

}  // namespace
}  // namespace piezoshift::host
