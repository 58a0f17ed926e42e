#include "piezoshift/design/design_inputs.hpp"
#include "piezoshift/core/bounds.hpp"

#include <fmt/core.h>

#include "piezoshift/design/design_ranges.hpp"

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
  std::string problem;
  visit_design_values(in, [&](const char* section, const char* key, double value, core::Bounds b) {
    if (problem.empty())
      problem = core::range_problem(fmt::format("{}.{}", section, key), value, b);
  });
  if (!problem.empty())
    return problem;
  return hinge_geometry_problem(in.hinge);
}

}  // namespace piezoshift::design
