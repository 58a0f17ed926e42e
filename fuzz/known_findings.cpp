#include "known_findings.hpp"

#include <array>
#include <string_view>

namespace piezoshift::fuzz {

bool is_known_finding(const std::exception& e) {
  static constexpr std::array<std::string_view, 2> kKnown{
      // `analyze repeatability` on data spread over more than 10 um, or huge values.
      "histogram: more than 10000 bins",
      "histogram: non-finite value",
  };
  const std::string_view what = e.what();
  for (std::string_view known : kKnown)
    if (what.starts_with(known))
      return true;
  return false;
}

}  // namespace piezoshift::fuzz
