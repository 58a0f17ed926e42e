#include "piezoshift/design/flexure.hpp"

#include <cmath>
#include <numbers>

namespace piezoshift::design {

double hinge_angular_stiffness_Nm_per_rad(const MaterialParams& material,
                                          const HingeParams& hinge) {
  return 2.0 * material.elastic_modulus_Pa * hinge.width_m * std::pow(hinge.thickness_m, 2.5) /
         (9.0 * std::numbers::pi * std::sqrt(hinge.radius_m));
}

double mechanism_stiffness_N_per_um(const MaterialParams& material, const HingeParams& hinge) {
  const double k_N_per_m = 8.0 * hinge_angular_stiffness_Nm_per_rad(material, hinge) /
                           (hinge.link_length_m * hinge.link_length_m);
  return k_N_per_m * 1e-6;
}

double mechanism_stiffness_closed_form_N_per_um(const MaterialParams& material,
                                                const HingeParams& hinge) {
  const double L = hinge.link_length_m;
  const double k_N_per_m = 16.0 * material.elastic_modulus_Pa * hinge.width_m *
                           std::pow(hinge.thickness_m, 2.5) /
                           (9.0 * std::numbers::pi * L * L * std::sqrt(hinge.radius_m));
  return k_N_per_m * 1e-6;
}

double available_displacement_um(const ActuatorParams& actuator,
                                 double mechanism_stiffness_N_per_um) {
  return actuator.nominal_stroke_um * actuator.stiffness_N_per_um /
         (actuator.stiffness_N_per_um + mechanism_stiffness_N_per_um);
}

double stiffness_rule_limit_N_per_um(const ActuatorParams& actuator) {
  return actuator.stiffness_N_per_um / 10.0;
}

bool meets_stiffness_rule(const ActuatorParams& actuator, double mechanism_stiffness_N_per_um) {
  return mechanism_stiffness_N_per_um < stiffness_rule_limit_N_per_um(actuator);
}

}  // namespace piezoshift::design
