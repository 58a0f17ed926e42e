#include "piezoshift/design/hinge_stress.hpp"

#include <cmath>

#include "piezoshift/design/flexure.hpp"

namespace piezoshift::design {

double hinge_rotation_rad(const HingeParams& hinge, double displacement_um) {
  return displacement_um * 1e-6 / hinge.link_length_m;
}

double stress_concentration_factor(const HingeParams& hinge) {
  return std::pow(1.0 + hinge.thickness_m / (2.0 * hinge.radius_m), 9.0 / 20.0);
}

double hinge_bending_moment_Nm(const MaterialParams& material, const HingeParams& hinge,
                               double displacement_um) {
  return hinge_angular_stiffness_Nm_per_rad(material, hinge) *
         hinge_rotation_rad(hinge, displacement_um);
}

double nominal_hinge_stress_Pa(const MaterialParams& material, const HingeParams& hinge,
                               double displacement_um) {
  const double t = hinge.thickness_m;
  return 6.0 * hinge_bending_moment_Nm(material, hinge, displacement_um) / (hinge.width_m * t * t);
}

double max_hinge_stress_Pa(const MaterialParams& material, const HingeParams& hinge,
                           double displacement_um) {
  return stress_concentration_factor(hinge) *
         nominal_hinge_stress_Pa(material, hinge, displacement_um);
}

}  // namespace piezoshift::design
