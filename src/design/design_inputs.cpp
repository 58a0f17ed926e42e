#include "piezoshift/design/design_inputs.hpp"

#include <cmath>
#include <utility>

#include <fmt/core.h>

namespace piezoshift::design {

std::string hinge_geometry_problem(const HingeParams& hinge) {
  if (!(hinge.thickness_m < 2.0 * hinge.radius_m)) {
    return fmt::format(
        "hinge.thickness_m = {} must be less than 2 * hinge.radius_m = {} (a notch hinge's neck is "
        "thinner than the notch diameter)",
        hinge.thickness_m, 2.0 * hinge.radius_m);
  }
  if (!(hinge.link_length_m > 2.0 * hinge.radius_m)) {
    return fmt::format(
        "hinge.link_length_m = {} must be more than 2 * hinge.radius_m = {} (the notches at the "
        "two ends of a link would overlap)",
        hinge.link_length_m, 2.0 * hinge.radius_m);
  }
  return {};
}

std::string design_inputs_problem(const DesignInputs& in) {
  const std::pair<const char*, double> positive[] = {
      {"actuator.stiffness_N_per_um", in.actuator.stiffness_N_per_um},
      {"actuator.nominal_stroke_um", in.actuator.nominal_stroke_um},
      {"actuator.pushing_force_N", in.actuator.pushing_force_N},
      {"actuator.pulling_force_N", in.actuator.pulling_force_N},
      {"actuator.capacitance_F", in.actuator.capacitance_F},
      {"actuator.resonance_frequency_Hz", in.actuator.resonance_frequency_Hz},
      {"actuator.length_m", in.actuator.length_m},
      {"material.elastic_modulus_Pa", in.material.elastic_modulus_Pa},
      {"material.density_kg_per_m3", in.material.density_kg_per_m3},
      {"material.allowable_stress_Pa", in.material.allowable_stress_Pa},
      {"hinge.width_m", in.hinge.width_m},
      {"hinge.thickness_m", in.hinge.thickness_m},
      {"hinge.radius_m", in.hinge.radius_m},
      {"hinge.link_length_m", in.hinge.link_length_m},
      {"mechanism.moving_mass_kg", in.mechanism.moving_mass_kg},
  };
  for (const auto& [name, value] : positive) {
    if (!(std::isfinite(value) && value > 0.0))
      return fmt::format("{} = {} must be a positive finite number", name, value);
  }
  const double nu = in.material.poisson_ratio;
  if (!(nu > 0.0 && nu < 0.5))
    return fmt::format("material.poisson_ratio = {} must be in (0, 0.5)", nu);
  return hinge_geometry_problem(in.hinge);
}

}  // namespace piezoshift::design
