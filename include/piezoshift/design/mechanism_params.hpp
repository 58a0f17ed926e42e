#pragma once
// The moving mass of one double parallel four-bar mechanism (paper, Section 2.2, Figure 2c).

namespace piezoshift::design {

//! The mechanism's effective moving mass in the actuated direction. Not in the paper's tables:
//! the default is the mass for which the mechanism stiffness of Eq. 3 (6.776 N/um) gives the
//! paper's FEA mode of 1839 Hz (Section 2.2, Figure 2c): m = k_m / (2 pi 1839 Hz)^2.
struct MechanismParams {
  double moving_mass_kg = 0.05075;  //!< m [kg], fitted to Figure 2c (1839 Hz)

  bool operator==(const MechanismParams&) const = default;
};

}  // namespace piezoshift::design
