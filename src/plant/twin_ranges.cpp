#include "piezoshift/plant/twin_ranges.hpp"
#include "piezoshift/core/bounds.hpp"

#include <fmt/core.h>

namespace piezoshift::plant {

std::string twin_ranges_problem(const TwinParams& twin) {
  std::string problem;
  visit_twin_values(
      twin, [&](const char* section, const char* key, const auto& value, core::Bounds bounds) {
        if (problem.empty())
          problem = core::range_problem(fmt::format("{}.{}", section, key), value, bounds);
      });
  return problem;
}

}  // namespace piezoshift::plant
