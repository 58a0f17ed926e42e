#pragma once
// Maximum bending stress in the hinges at a given mechanism displacement (not in the paper,
// which checks stress by FEA only, Figure 2b).
//
// Each hinge of a parallel four-bar turns theta = x / L when the mechanism moves x (the same
// kinematics that give Eq. 3). The hinge then carries the bending moment M = k_alpha_z theta
// (Eq. 2). The nominal stress at the neck is that of a rectangular section b x t in bending,
//   sigma_nom = 6 M / (b t^2),
// and the notch raises it by the stress concentration factor fitted by Yong, Lu & Handley,
// "Review of circular flexure hinge design equations and derivation of empirical formulations",
// Precis. Eng. 32 (2008) 63-70 (the paper's ref. [22]), for right-circular hinges in bending:
//   K_t = (1 + t / (2 R))^(9/20),
//   sigma_max = K_t sigma_nom.
// With Tables 1 to 3 at x_m = 14.59 um: sigma_max = 44.7 MPa (the paper's FEA: 47.63 MPa).
#include "piezoshift/design/hinge_params.hpp"
#include "piezoshift/design/material_params.hpp"

namespace piezoshift::design {

//! theta = x / L, the rotation of each hinge at mechanism displacement x [rad].
double hinge_rotation_rad(const HingeParams& hinge, double displacement_um);

//! K_t = (1 + t / (2 R))^(9/20), Yong, Lu & Handley (2008), right-circular hinge in bending [-].
double stress_concentration_factor(const HingeParams& hinge);

//! M = k_alpha_z x / L, the bending moment in each hinge at mechanism displacement x [N m].
double hinge_bending_moment_Nm(const MaterialParams& material, const HingeParams& hinge,
                               double displacement_um);

//! sigma_nom = 6 M / (b t^2), the neck's bending stress without the notch effect [Pa].
double nominal_hinge_stress_Pa(const MaterialParams& material, const HingeParams& hinge,
                               double displacement_um);

//! sigma_max = K_t 6 M / (b t^2), the largest stress in the hinges [Pa].
double max_hinge_stress_Pa(const MaterialParams& material, const HingeParams& hinge,
                           double displacement_um);

}  // namespace piezoshift::design
