#include "piezoshift/design/flexure.hpp"

#include <cmath>

#include <gtest/gtest.h>

namespace piezoshift::design {
namespace {

// A second geometry, computed by hand (aluminium, E = 70 GPa):
//   b = 10 mm, t = 1.5 mm, R = 5 mm, L = 20 mm
//   t^(5/2)   = (1.5e-3)^2 * sqrt(1.5e-3) = 2.25e-6 * 0.0387298 = 8.71421e-8 m^(5/2)
//   k_alpha_z = 2 * 70e9 * 0.010 * 8.71421e-8 / (9 pi sqrt(5e-3))
//             = 121.999 / (28.2743 * 0.0707107) = 121.999 / 1.99930 = 61.021 N m/rad
//   k_m       = 8 * 61.021 / 0.020^2 = 1.22042e6 N/m = 1.2204 N/um
//   x_m       = 16 um * 70 / (70 + 1.2204) = 15.7258 um          (paper's actuator, Table 1)
MaterialParams aluminium() {
  MaterialParams m;
  m.elastic_modulus_Pa = 70e9;
  return m;
}
HingeParams second_hinge() {
  return HingeParams{
      .width_m = 10e-3, .thickness_m = 1.5e-3, .radius_m = 5e-3, .link_length_m = 20e-3};
}

TEST(Flexure, PaperTablesGiveSection22Values) {
  // Section 2.2: k_m = 6.78 N/um, x_m ~ 14.6 um; k_alpha_z from Eq. 2 by hand: 274.44 N m/rad.
  EXPECT_NEAR(hinge_angular_stiffness_Nm_per_rad({}, {}), 274.44, 0.01);
  const double km = mechanism_stiffness_N_per_um({}, {});
  EXPECT_NEAR(km, 6.776, 0.001);
  EXPECT_NEAR(std::round(km * 100.0) / 100.0, 6.78, 1e-12);  // the paper's rounding
  EXPECT_NEAR(available_displacement_um({}, km), 14.588, 0.001);
}

TEST(Flexure, SecondGeometryMatchesHandCalculation) {
  EXPECT_NEAR(hinge_angular_stiffness_Nm_per_rad(aluminium(), second_hinge()), 61.021, 0.001);
  const double km = mechanism_stiffness_N_per_um(aluminium(), second_hinge());
  EXPECT_NEAR(km, 1.2204, 0.0001);
  EXPECT_NEAR(available_displacement_um({}, km), 15.7258, 0.0001);
}

TEST(Flexure, Eq4FromEqs2And3HasTToTheFiveHalves) {
  // The corrected Eq. 4 must agree with Eq. 3 applied to Eq. 2, for both geometries...
  EXPECT_NEAR(mechanism_stiffness_closed_form_N_per_um({}, {}),
              mechanism_stiffness_N_per_um({}, {}), 1e-12);
  EXPECT_NEAR(mechanism_stiffness_closed_form_N_per_um(aluminium(), second_hinge()),
              mechanism_stiffness_N_per_um(aluminium(), second_hinge()), 1e-12);
  // ...and scale as t^(5/2): doubling t multiplies k_m by 2^2.5 = 5.657, not 2^5 = 32.
  HingeParams thick;
  thick.thickness_m *= 2.0;
  EXPECT_NEAR(mechanism_stiffness_closed_form_N_per_um({}, thick) /
                  mechanism_stiffness_closed_form_N_per_um({}, {}),
              std::pow(2.0, 2.5), 1e-9);
}

TEST(Flexure, StiffnessRuleIsKaOverTenStrict) {
  EXPECT_DOUBLE_EQ(stiffness_rule_limit_N_per_um({}), 7.0);
  EXPECT_TRUE(meets_stiffness_rule({}, 6.776));
  EXPECT_FALSE(meets_stiffness_rule({}, 7.0));  // "under 1/10", Section 2.2
  EXPECT_FALSE(meets_stiffness_rule({}, 7.5));
}

TEST(Flexure, MechanismAtTheRuleLimitKeepsTenEleventhsOfTheStroke) {
  // x_m = x_a k_a / (k_a + k_a/10) = x_a / 1.1.
  EXPECT_NEAR(available_displacement_um({}, 7.0), 16.0 / 1.1, 1e-12);
  EXPECT_DOUBLE_EQ(available_displacement_um({}, 0.0), 16.0);
}

}  // namespace
}  // namespace piezoshift::design
