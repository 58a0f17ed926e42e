#pragma once
// Everything the flexure design depends on, in one value: Tables 1 to 3 and the moving mass.
#include <string>

#include "piezoshift/design/actuator_params.hpp"
#include "piezoshift/design/hinge_params.hpp"
#include "piezoshift/design/material_params.hpp"
#include "piezoshift/design/mechanism_params.hpp"

namespace piezoshift::design {

struct DesignInputs {
  ActuatorParams actuator;    //!< Table 1
  MaterialParams material;    //!< Table 2
  HingeParams hinge;          //!< Table 3
  MechanismParams mechanism;  //!< moving mass, fitted to Figure 2c

  bool operator==(const DesignInputs&) const = default;
};

//! Why a hinge cannot be built as drawn in Figure 1, or "" when it can:
//!   t < 2 R  (the neck is thinner than the notch diameter; otherwise it is no notch hinge), and
//!   L > 2 R  (the two notches at the ends of a link must not overlap).
//! Assumes every dimension is already positive and finite.
std::string hinge_geometry_problem(const HingeParams& hinge);

//! Why inputs are not physical, or "" when they are: every number within its range
//! (design_ranges.hpp; the value is named in the message), then hinge_geometry_problem().
std::string design_inputs_problem(const DesignInputs& inputs);

}  // namespace piezoshift::design
