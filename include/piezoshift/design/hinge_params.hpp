#pragma once
// Dimensions of one right-circular flexure hinge and of the bar linkage (paper, Figure 1, Table 3).
// A hinge is two circular notches of radius R cut face to face, leaving a neck of thickness t.
#include "piezoshift/design/mechanism_params.hpp"  // MechanismParams lived here first

namespace piezoshift::design {

struct HingeParams {
  double width_m = 8e-3;         //!< b, Table 3 (out-of-plane width)
  double thickness_m = 2e-3;     //!< t, Table 3 (thinnest section of the notch)
  double radius_m = 6e-3;        //!< R, Table 3 (notch radius)
  double link_length_m = 18e-3;  //!< L, Table 3 (bar linkage length, hinge centre to centre)

  bool operator==(const HingeParams&) const = default;
};

}  // namespace piezoshift::design
