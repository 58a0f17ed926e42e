#pragma once
// Flexure design equations (paper, Section 2.2, Eqs. 1 to 4) for the double parallel four-bar
// mechanism of eight right-circular hinges (Figure 1):
//
//   Eq. 2  k_alpha_z = 2 E b t^(5/2) / (9 pi R^(1/2))        one hinge, about its z-axis [N m/rad]
//   Eq. 3  k_m       = 8 k_alpha_z / L^2                     mechanism, actuated direction [N/m]
//   Eq. 4  k_m       = 16 E b t^(5/2) / (9 pi L^2 R^(1/2))   Eqs. 2 and 3 combined; the paper
//                                                            prints t^5, an erratum
//                                                            (docs/design.md)
//   Eq. 1  x_m       = x_a k_a / (k_a + k_m)                 stroke left under the mechanism's load
//   rule   k_m < k_a / 10                                    loses less than ~9 % of the stroke
//
// Eq. 3 follows from the energy of the eight hinges, each turning theta = x / L at mechanism
// displacement x: U = 8 (1/2) k_alpha_z (x/L)^2 = (1/2) k_m x^2. Eq. 2 is the simplified
// right-circular hinge formula, meant for thin necks (t much smaller than R).
#include "piezoshift/design/actuator_params.hpp"
#include "piezoshift/design/hinge_params.hpp"
#include "piezoshift/design/material_params.hpp"

namespace piezoshift::design {

//! Eq. 2: k_alpha_z = 2 E b t^(5/2) / (9 pi R^(1/2)), one right-circular hinge [N m/rad].
double hinge_angular_stiffness_Nm_per_rad(const MaterialParams& material, const HingeParams& hinge);

//! Eq. 3: k_m = 8 k_alpha_z / L^2, the double parallel four-bar mechanism [N/um].
double mechanism_stiffness_N_per_um(const MaterialParams& material, const HingeParams& hinge);

//! Eq. 4 as it follows from Eqs. 2 and 3: k_m = 16 E b t^(5/2) / (9 pi L^2 R^(1/2)) [N/um].
//! Equal to mechanism_stiffness_N_per_um(); kept apart so a test pins the erratum.
double mechanism_stiffness_closed_form_N_per_um(const MaterialParams& material,
                                                const HingeParams& hinge);

//! Eq. 1: x_m = x_a k_a / (k_a + k_m), the stroke left under the mechanism's load [um].
double available_displacement_um(const ActuatorParams& actuator,
                                 double mechanism_stiffness_N_per_um);

//! The design rule of Section 2.2: the largest mechanism stiffness allowed, k_a / 10 [N/um].
double stiffness_rule_limit_N_per_um(const ActuatorParams& actuator);

//! The design rule of Section 2.2, k_m < k_a / 10 (strict, as the paper states it).
bool meets_stiffness_rule(const ActuatorParams& actuator, double mechanism_stiffness_N_per_um);

}  // namespace piezoshift::design
