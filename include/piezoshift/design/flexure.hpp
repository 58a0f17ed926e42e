#pragma once
// Flexure design equations (paper, Section 2.2, Eqs. 1 to 3).
#include "piezoshift/design/actuator_params.hpp"
#include "piezoshift/design/hinge_params.hpp"
#include "piezoshift/design/material_params.hpp"

namespace piezoshift::design {

//! Eq. 2: k_alpha_z = 2 E b t^(5/2) / (9 pi R^(1/2)), one right-circular hinge [N m/rad].
double hinge_angular_stiffness_Nm_per_rad(const MaterialParams& material, const HingeParams& hinge);

//! Eq. 3: k_m = 8 k_alpha_z / L^2, the double parallel four-bar mechanism [N/um].
double mechanism_stiffness_N_per_um(const MaterialParams& material, const HingeParams& hinge);

//! Eq. 1: x_m = x_a k_a / (k_a + k_m), the stroke left under the mechanism's load [um].
double available_displacement_um(const ActuatorParams& actuator,
                                 double mechanism_stiffness_N_per_um);

}  // namespace piezoshift::design
