#include "piezoshift/design/design_evaluation.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>

namespace piezoshift::design {
namespace {

TEST(DesignEvaluation, PaperDesignReport) {
  const DesignEvaluation e = evaluate_design({});
  EXPECT_NEAR(e.hinge_angular_stiffness_Nm_per_rad, 274.44, 0.01);
  EXPECT_NEAR(e.mechanism_stiffness_N_per_um, 6.776, 0.001);
  EXPECT_DOUBLE_EQ(e.stiffness_rule_limit_N_per_um, 7.0);
  EXPECT_NEAR(e.stiffness_ratio, 6.776 / 70.0, 1e-4);
  EXPECT_TRUE(e.rule_ka_over_10_ok);
  EXPECT_NEAR(e.available_displacement_um, 14.588, 0.001);
  EXPECT_NEAR(e.stroke_loss_percent, 100.0 * (1.0 - 14.5878 / 16.0), 0.001);
  EXPECT_NEAR(e.spring_force_at_stroke_N, 6.7763 * 14.5878, 0.01);  // 98.85 N
  EXPECT_TRUE(e.force_within_pushing_limit);                        // 1400 N, Table 1
  EXPECT_NEAR(e.stress_concentration_factor, 1.07183, 1e-5);
  EXPECT_NEAR(e.max_stress_at_stroke_Pa, 44.70e6, 0.01e6);
  EXPECT_DOUBLE_EQ(e.allowable_stress_Pa, 355e6);
  EXPECT_NEAR(e.stress_margin, 355.0 / 44.698, 0.001);  // 7.94
  EXPECT_TRUE(e.stress_ok);
  EXPECT_NEAR(e.natural_frequency_Hz, 1839.0, 0.5);
  EXPECT_NEAR(e.thickness_to_radius, 1.0 / 3.0, 1e-12);
}

TEST(DesignEvaluation, StiffHingeBreaksTheRuleAndAnOverloadedOneTheStress) {
  DesignInputs in;
  in.hinge.thickness_m = 2.1e-3;  // k_m = 6.776 * 1.05^2.5 = 7.64 N/um > 7
  EXPECT_FALSE(evaluate_design(in).rule_ka_over_10_ok);
  in = {};
  in.material.allowable_stress_Pa = 40e6;  // below the 44.7 MPa at full stroke
  const DesignEvaluation e = evaluate_design(in);
  EXPECT_FALSE(e.stress_ok);
  EXPECT_NEAR(e.stress_margin, 40.0 / 44.698, 0.001);
}

TEST(DesignEvaluation, RejectsNonPhysicalInputs) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto with = [](auto edit) {
    DesignInputs in;
    edit(in);
    return in;
  };
  EXPECT_THROW(evaluate_design(with([](DesignInputs& in) { in.hinge.width_m = 0.0; })),
               std::invalid_argument);
  EXPECT_THROW(evaluate_design(with([](DesignInputs& in) { in.actuator.stiffness_N_per_um = -1; })),
               std::invalid_argument);
  EXPECT_THROW(
      evaluate_design(with([nan](DesignInputs& in) { in.material.elastic_modulus_Pa = nan; })),
      std::invalid_argument);
  EXPECT_THROW(evaluate_design(with([](DesignInputs& in) { in.material.poisson_ratio = 0.5; })),
               std::invalid_argument);
  EXPECT_THROW(evaluate_design(with([](DesignInputs& in) { in.hinge.thickness_m = 12e-3; })),
               std::invalid_argument);  // t = 2R
  EXPECT_THROW(evaluate_design(with([](DesignInputs& in) { in.hinge.link_length_m = 12e-3; })),
               std::invalid_argument);  // L = 2R
  EXPECT_THROW(evaluate_design(with([](DesignInputs& in) { in.mechanism.moving_mass_kg = 0; })),
               std::invalid_argument);
}

TEST(DesignInputs, ProblemsNameTheField) {
  DesignInputs in;
  EXPECT_EQ(design_inputs_problem(in), "");
  in.material.density_kg_per_m3 = -5.0;
  EXPECT_NE(design_inputs_problem(in).find("material.density_kg_per_m3"), std::string::npos);
  in = {};
  in.hinge.thickness_m = 13e-3;
  const std::string p = design_inputs_problem(in);
  EXPECT_NE(p.find("hinge.thickness_m"), std::string::npos);
  EXPECT_NE(p.find("hinge.radius_m"), std::string::npos);
}

}  // namespace
}  // namespace piezoshift::design
