#include "piezoshift/reproduction/figure_format.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

namespace piezoshift::reproduction {
namespace {

// Decimals that keep `significant` significant figures of v.
int significant_decimals(double v, int significant) {
  const int magnitude = static_cast<int>(std::floor(std::log10(std::fabs(v))));
  return std::clamp(significant - 1 - magnitude, 0, 6);
}

// Decimals of a resolution (0.1 -> 1, 0.25 -> 2, 1 -> 0).
int resolution_decimals(double resolution) {
  for (int d = 0; d < 6; ++d) {
    const double scaled = resolution * std::pow(10.0, d);
    if (std::fabs(scaled - std::round(scaled)) < 1e-9)
      return d;
  }
  return 6;
}

}  // namespace

std::string unit_symbol(std::string_view unit) {
  if (unit == "um")
    return "µm";
  if (unit == "deg")
    return "°";
  return std::string(unit);
}

std::string format_figure(double value, std::string_view unit, double resolution) {
  if (std::isnan(value))
    return "-";
  if (unit == "s") {
    if (std::isinf(value))
      return "not settled";
    const double ms = 1e3 * value;
    if (std::fabs(ms) >= 1000.0)
      return fmt::format("{:.2f} s", value);
    return fmt::format("{:.{}f} ms", ms, std::fabs(ms) < 10.0 ? 1 : 0);
  }
  if (std::isinf(value))
    return "none";
  const std::string symbol = unit_symbol(unit);
  const std::string sep = unit == "deg" ? "" : " ";
  if (value == 0.0)
    return "0" + sep + symbol;
  int decimals = 2;
  if (resolution > 0.0)
    decimals = resolution_decimals(resolution);
  else if (unit == "nm" || unit == "%")
    decimals = significant_decimals(value, 2);
  else if (unit == "dB" || unit == "deg")
    decimals = 1;
  else if (unit != "um")
    decimals = significant_decimals(value, 3);
  return fmt::format("{:.{}f}{}{}", value, decimals, sep, symbol);
}

}  // namespace piezoshift::reproduction
