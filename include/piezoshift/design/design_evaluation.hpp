#pragma once
// The whole flexure design report, computed from one DesignInputs: stiffness (Eqs. 2 to 4), the
// k_a / 10 rule, the available stroke (Eq. 1), the force the actuator must push at that stroke,
// the hinge stress at that stroke (hinge_stress.hpp) and the first natural frequency
// (natural_frequency.hpp). "At stroke" means at x_m, the full available displacement.
#include "piezoshift/design/design_inputs.hpp"

namespace piezoshift::design {

struct DesignEvaluation {
  double hinge_angular_stiffness_Nm_per_rad = 0.0;  //!< k_alpha_z, Eq. 2
  double mechanism_stiffness_N_per_um = 0.0;        //!< k_m, Eq. 3
  double stiffness_rule_limit_N_per_um = 0.0;       //!< k_a / 10, Section 2.2
  double stiffness_ratio = 0.0;                     //!< k_m / k_a [-]
  bool rule_ka_over_10_ok = false;                  //!< k_m < k_a / 10

  double available_displacement_um = 0.0;   //!< x_m, Eq. 1
  double stroke_loss_percent = 0.0;         //!< 100 (1 - x_m / x_a)
  double spring_force_at_stroke_N = 0.0;    //!< k_m x_m, the mechanism's push back on the actuator
  bool force_within_pushing_limit = false;  //!< k_m x_m <= the actuator's pushing force

  double hinge_rotation_at_stroke_rad = 0.0;  //!< theta = x_m / L
  double hinge_moment_at_stroke_Nm = 0.0;     //!< M = k_alpha_z theta
  double stress_concentration_factor = 0.0;   //!< K_t = (1 + t/(2R))^(9/20)
  double nominal_stress_at_stroke_Pa = 0.0;   //!< 6 M / (b t^2)
  double max_stress_at_stroke_Pa = 0.0;       //!< K_t 6 M / (b t^2)
  double allowable_stress_Pa = 0.0;           //!< Table 2
  double stress_margin = 0.0;                 //!< allowable / max stress [-]
  bool stress_ok = false;                     //!< stress_margin >= 1

  double natural_frequency_Hz = 0.0;  //!< sqrt(k_m / m) / (2 pi)
  double thickness_to_radius = 0.0;   //!< t / R; Eq. 2 is meant for t much smaller than R
};

//! Evaluates a design. Throws std::invalid_argument when design_inputs_problem() finds one (the
//! configuration loader reports such inputs as core::InputError before they get here).
DesignEvaluation evaluate_design(const DesignInputs& inputs);

}  // namespace piezoshift::design
