#include "piezoshift/design/design_evaluation.hpp"

#include <stdexcept>

#include "piezoshift/design/flexure.hpp"
#include "piezoshift/design/hinge_stress.hpp"
#include "piezoshift/design/natural_frequency.hpp"

namespace piezoshift::design {

DesignEvaluation evaluate_design(const DesignInputs& in) {
  if (const std::string problem = design_inputs_problem(in); !problem.empty())
    throw std::invalid_argument("evaluate_design: " + problem);

  const ActuatorParams& act = in.actuator;
  DesignEvaluation e;
  e.hinge_angular_stiffness_Nm_per_rad = hinge_angular_stiffness_Nm_per_rad(in.material, in.hinge);
  e.mechanism_stiffness_N_per_um = mechanism_stiffness_N_per_um(in.material, in.hinge);
  e.stiffness_rule_limit_N_per_um = stiffness_rule_limit_N_per_um(act);
  e.stiffness_ratio = e.mechanism_stiffness_N_per_um / act.stiffness_N_per_um;
  e.rule_ka_over_10_ok = meets_stiffness_rule(act, e.mechanism_stiffness_N_per_um);

  const double x_m = available_displacement_um(act, e.mechanism_stiffness_N_per_um);
  e.available_displacement_um = x_m;
  e.stroke_loss_percent = 100.0 * (1.0 - x_m / act.nominal_stroke_um);
  e.spring_force_at_stroke_N = e.mechanism_stiffness_N_per_um * x_m;
  e.force_within_pushing_limit = e.spring_force_at_stroke_N <= act.pushing_force_N;

  e.hinge_rotation_at_stroke_rad = hinge_rotation_rad(in.hinge, x_m);
  e.hinge_moment_at_stroke_Nm = hinge_bending_moment_Nm(in.material, in.hinge, x_m);
  e.stress_concentration_factor = stress_concentration_factor(in.hinge);
  e.nominal_stress_at_stroke_Pa = nominal_hinge_stress_Pa(in.material, in.hinge, x_m);
  e.max_stress_at_stroke_Pa = max_hinge_stress_Pa(in.material, in.hinge, x_m);
  e.allowable_stress_Pa = in.material.allowable_stress_Pa;
  e.stress_margin = e.allowable_stress_Pa / e.max_stress_at_stroke_Pa;
  e.stress_ok = e.stress_margin >= 1.0;

  e.natural_frequency_Hz =
      natural_frequency_Hz(e.mechanism_stiffness_N_per_um, in.mechanism.moving_mass_kg);
  e.thickness_to_radius = in.hinge.thickness_m / in.hinge.radius_m;
  return e;
}

}  // namespace piezoshift::design
