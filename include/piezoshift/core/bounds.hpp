#pragma once
// The valid range of one parameter value, and the check every reader of that value shares (the
// TOML reader, the Python bindings, the model builders). It lives in the lowest module so that
// each parameter struct can state its ranges next to itself (design_ranges.hpp,
// plant/twin_ranges.hpp) and io::ConfigSection reads every value against it.
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace piezoshift::core {

//! Allowed range for a number; the bound is open (excluded) where the flag says so. NaN and
//! infinity are never contained.
struct Bounds {
  double lo = -1e308;
  double hi = 1e308;
  bool lo_open = false;
  bool hi_open = false;

  static constexpr Bounds any() { return {}; }
  static constexpr Bounds positive() { return {0.0, 1e308, true, false}; }
  static constexpr Bounds non_negative() { return {0.0, 1e308, false, false}; }
  static constexpr Bounds closed(double lo, double hi) { return {lo, hi, false, false}; }
  static constexpr Bounds open(double lo, double hi) { return {lo, hi, true, true}; }
  //! (lo, hi]: e.g. a positive value with a stated maximum.
  static constexpr Bounds above(double lo, double hi) { return {lo, hi, true, false}; }

  bool contains(double v) const;
  std::string describe() const;  //!< e.g. "> 0" or "in [0, 1]"
};

//! "" when value is within bounds, else "<path> = <value> must be <bounds>" (an element of a list
//! is named path[i], of a matrix path[r][c]; an absent optional is always valid).
std::string range_problem(std::string_view path, double value, const Bounds& bounds);
std::string range_problem(std::string_view path, std::int64_t value, const Bounds& bounds);
std::string range_problem(std::string_view path, const std::array<double, 3>& value,
                          const Bounds& bounds);
std::string range_problem(std::string_view path, const std::array<std::array<double, 3>, 3>& value,
                          const Bounds& bounds);
std::string range_problem(std::string_view path, const std::optional<double>& value,
                          const Bounds& bounds);

}  // namespace piezoshift::core
