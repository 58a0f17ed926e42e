#pragma once
// Dimensions of one right-circular flexure hinge and of the bar linkage (paper, Figure 1, Table 3),
// and the moving mass of one double parallel four-bar mechanism.

namespace piezoshift::design {

struct HingeParams {
  double width_m = 8e-3;         //!< b, Table 3
  double thickness_m = 2e-3;     //!< t, Table 3 (thinnest section of the notch)
  double radius_m = 6e-3;        //!< R, Table 3 (notch radius)
  double link_length_m = 18e-3;  //!< L, Table 3 (bar linkage length)
};

//! The mechanism's effective moving mass in the actuated direction. Not in the paper's tables:
//! the default is the mass for which the mechanism stiffness of Eq. 3 (6.776 N/um) gives the
//! paper's FEA mode of 1839 Hz (Section 2.2, Figure 2c): m = k_m / (2 pi 1839 Hz)^2.
struct MechanismParams {
  double moving_mass_kg = 0.05075;
};

}  // namespace piezoshift::design
