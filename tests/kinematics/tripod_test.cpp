#include "piezoshift/kinematics/tripod.hpp"

#include <stdexcept>

#include <gtest/gtest.h>

namespace piezoshift::kinematics {
namespace {

// Eq. 5 by hand, with L12 = 60 mm and L23 = 69.282 mm (an equilateral triangle of side 69.282 mm).
TEST(Tripod, PaperLayoutForwardIsEquation5) {
  const double l12 = 0.060, l23 = 0.069282;
  const TripodGeometry g = TripodGeometry::paper_layout(l12, l23);
  const PointDisplacements z{5.0, 4.0, 3.0};
  const PlatePose pose = g.forward(z);
  EXPECT_NEAR(pose.z_um, 4.0, 1e-12);                                       // (5+4+3)/3
  EXPECT_NEAR(pose.theta_x_urad, (2 * 5.0 - 4.0 - 3.0) / (2 * l12), 1e-9);  // 25 urad
  EXPECT_NEAR(pose.theta_y_urad, (4.0 - 3.0) / l23, 1e-9);                  // 14.434 urad
  EXPECT_NEAR(pose.theta_x_urad, 25.0, 1e-9);
  EXPECT_NEAR(pose.theta_y_urad, 14.43376, 1e-5);
}

TEST(Tripod, ForwardInverseRoundTripOnAnIrregularTriangle) {
  const TripodGeometry g(
      {PlatePoint{0.01, 0.04}, PlatePoint{-0.035, -0.01}, PlatePoint{0.03, -0.025}});
  const PlatePose pose{7.5, -12.0, 30.0};
  const PointDisplacements z = g.inverse(pose);
  const PlatePose back = g.forward(z);
  EXPECT_NEAR(back.z_um, 7.5, 1e-10);
  EXPECT_NEAR(back.theta_x_urad, -12.0, 1e-9);
  EXPECT_NEAR(back.theta_y_urad, 30.0, 1e-9);
  // z(x, y) = Z + theta_x y - theta_y x at P1 = (0.01, 0.04): 7.5 - 0.48 - 0.3 = 6.72 um
  EXPECT_NEAR(z[0], 6.72, 1e-12);
}

TEST(Tripod, PureTiltAboutXLeavesTheCentroidStill) {
  const TripodGeometry g = TripodGeometry::on_circle(0.05, 1.5707963267948966);
  const PointDisplacements z = g.inverse(PlatePose{0.0, 100.0, 0.0});
  EXPECT_NEAR(z[0], 5.0, 1e-12);   // at y = 0.05 m: 100 urad * 0.05 m = 5 um
  EXPECT_NEAR(z[1], -2.5, 1e-12);  // at y = -0.025 m
  EXPECT_NEAR(g.forward(z).z_um, 0.0, 1e-12);
}

TEST(Tripod, CollinearPointsAreRejected) {
  EXPECT_THROW(TripodGeometry({PlatePoint{0, 0}, PlatePoint{0.01, 0.01}, PlatePoint{0.02, 0.02}}),
               std::invalid_argument);
  EXPECT_THROW(TripodGeometry::paper_layout(0.0, 0.05), std::invalid_argument);
}

}  // namespace
}  // namespace piezoshift::kinematics
