#include "piezoshift/core/bounds.hpp"

#include <cmath>

#include <fmt/core.h>

namespace piezoshift::core {

bool Bounds::contains(double v) const {
  if (!std::isfinite(v))
    return false;
  const bool above = lo_open ? v > lo : v >= lo;
  const bool below = hi_open ? v < hi : v <= hi;
  return above && below;
}

std::string Bounds::describe() const {
  const bool no_lo = lo <= -1e308, no_hi = hi >= 1e308;
  if (no_lo && no_hi)
    return "a finite number";
  if (no_hi)
    return fmt::format("{} {}", lo_open ? ">" : ">=", lo);
  if (no_lo)
    return fmt::format("{} {}", hi_open ? "<" : "<=", hi);
  return fmt::format("in {}{}, {}{}", lo_open ? "(" : "[", lo, hi, hi_open ? ")" : "]");
}

std::string range_problem(std::string_view path, double value, const Bounds& bounds) {
  if (bounds.contains(value))
    return {};
  return fmt::format("{} = {} must be {}", path, value, bounds.describe());
}

std::string range_problem(std::string_view path, std::int64_t value, const Bounds& bounds) {
  if (bounds.contains(static_cast<double>(value)))
    return {};
  return fmt::format("{} = {} must be {}", path, value, bounds.describe());
}

std::string range_problem(std::string_view path, const std::array<double, 3>& value,
                          const Bounds& bounds) {
  for (std::size_t i = 0; i < value.size(); ++i) {
    if (std::string p = range_problem(fmt::format("{}[{}]", path, i), value[i], bounds); !p.empty())
      return p;
  }
  return {};
}

std::string range_problem(std::string_view path, const std::array<std::array<double, 3>, 3>& value,
                          const Bounds& bounds) {
  for (std::size_t r = 0; r < value.size(); ++r) {
    for (std::size_t c = 0; c < value[r].size(); ++c) {
      if (std::string p = range_problem(fmt::format("{}[{}][{}]", path, r, c), value[r][c], bounds);
          !p.empty())
        return p;
    }
  }
  return {};
}

std::string range_problem(std::string_view path, const std::optional<double>& value,
                          const Bounds& bounds) {
  return value ? range_problem(path, *value, bounds) : std::string{};
}

}  // namespace piezoshift::core
