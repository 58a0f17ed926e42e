// Reproducers: twin settings the ranges let through failed later without naming their key
// (`[twin.amplifier] gain = 5e-324`, `[twin.daq] resolution_bits = 2`). Every key of the one
// range list (plant/twin_ranges.hpp) is set alone to each end of its range, the nearest value
// inside an open end (5e-324 for "> 0"): either make_twin_model refuses it naming the key, or the
// twin it builds stays finite and its stacks move when the DAQ asks them to.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include <gtest/gtest.h>

#include "piezoshift/core/bounds.hpp"
#include "piezoshift/plant/twin.hpp"
#include "piezoshift/plant/twin_model.hpp"
#include "piezoshift/plant/twin_ranges.hpp"

namespace piezoshift::plant {
namespace {

// The value just inside each end of b (its own value at a closed end).
std::vector<double> ends(const core::Bounds& b) {
  const double inf = std::numeric_limits<double>::infinity();
  return {b.lo_open ? std::nextafter(b.lo, inf) : b.lo,
          b.hi_open ? std::nextafter(b.hi, -inf) : b.hi};
}

// Sets every element of value to v.
template <class T>
void set_all(T& value, double v) {
  if constexpr (std::is_same_v<T, double>)
    value = v;
  else if constexpr (std::is_same_v<T, std::int64_t>)
    value = static_cast<std::int64_t>(v);
  else if constexpr (std::is_same_v<T, std::optional<double>>)
    value = v;
  else if constexpr (std::is_same_v<T, std::array<double, 3>>)
    value = {v, v, v};
  else
    for (auto& row : value)
      row = {v, v, v};
}

bool finite(const Vec3& v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

// "" when the twin stays finite and the stacks move; else what went wrong.
std::string run_problem(const TwinParams& params) {
  Twin twin({}, params, 1);
  // Ask for about a third of the stroke, for 0.2 s of control periods (at most 2000).
  const double ao = 0.3 * params.amplifier.output_max_V / params.amplifier.gain;
  twin.write_ao({ao, ao, ao});
  const auto ticks = static_cast<int>(std::fmin(2000.0, 0.2 / params.daq.sample_time_s) + 1.0);
  for (int k = 0; k < ticks; ++k)
    twin.advance();
  const TwinTruth& t = twin.truth();
  if (!finite(twin.read_ai()) || !finite(t.stack_elongation_um) || !finite(t.points_um) ||
      !finite(t.sgs_V) || !finite(twin.interferometer().dynamic_um))
    return "not finite after 0.2 s";
  for (double e : t.free_elongation_um)
    if (!(e > 0.01))
      return "a stack moved " + std::to_string(e) + " um for a third of its volts";
  return "";
}

std::string text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

struct Key {
  std::string name;  // section.key
  std::string key;
  core::Bounds bounds;
};

TEST(TwinRangesEdges, EveryAcceptedValueBuildsAFiniteTwinThatMovesEveryOtherIsNamed) {
  std::vector<Key> keys;
  TwinParams defaults;
  visit_twin_values(defaults, [&](const char* section, const char* key, auto&, core::Bounds b) {
    keys.push_back({std::string(section) + "." + key, key, b});
  });
  std::vector<std::string> failures;
  for (std::size_t i = 0; i < keys.size(); ++i) {
    for (double v : ends(keys[i].bounds)) {
      TwinParams p;
      std::size_t n = 0;
      visit_twin_values(p, [&](const char*, const char*, auto& field, core::Bounds) {
        if (n++ == i)
          set_all(field, v);
      });
      const std::string what = keys[i].name + " = " + text(v);
      const std::string refused = twin_params_problem({}, p);
      if (!refused.empty()) {
        if (refused.find(keys[i].key) == std::string::npos)
          failures.push_back(what + ": refused without its key: " + refused);
        continue;
      }
      try {
        if (const std::string why = run_problem(p); !why.empty())
          failures.push_back(what + ": " + why);
      } catch (const std::exception& e) {
        failures.push_back(what + ": threw " + e.what());
      }
    }
  }
  for (const std::string& f : failures)
    ADD_FAILURE() << f;
}

}  // namespace
}  // namespace piezoshift::plant
