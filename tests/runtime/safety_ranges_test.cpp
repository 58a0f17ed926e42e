// The [safety] section: every limit has a range, the pairs are checked, the file names the key,
// and the supervisor refuses what the reader refuses (one list, safety_ranges.hpp).
#include "piezoshift/runtime/safety_ranges.hpp"
#include "piezoshift/core/bounds.hpp"

#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "piezoshift/core/input_error.hpp"

namespace piezoshift::runtime {
namespace {

std::string error_of(const std::string& toml) {
  try {
    SafetyLimits l;
    read_safety_section(io::ConfigFile::parse(toml, "site.toml"), l);
  } catch (const core::InputError& e) {
    return e.what();
  }
  return {};
}

TEST(SafetyRanges, DefaultsAreInRangeAndEveryLimitIsListed) {
  EXPECT_EQ(safety_limits_problem(SafetyLimits{}), "");
  int n = 0;
  SafetyLimits l;
  visit_safety_limits(l, [&](const char*, const char*, auto&, core::Bounds) { ++n; });
  EXPECT_EQ(n, 23);  // every field of SafetyLimits (trip_on_overruns the 23rd)
}

TEST(SafetyRanges, SectionSetsLimitsAndRefusesOutOfRangeAndContradictions) {
  SafetyLimits l;
  read_safety_section(io::ConfigFile::parse(
                          "[safety]\noutput_max_V = 8.0\nmax_consecutive_overruns = 5\n", "s.toml"),
                      l);
  EXPECT_EQ(l.output_max_V, 8.0);
  EXPECT_EQ(l.max_consecutive_overruns, 5u);
  EXPECT_EQ(l.max_slew_V_per_s, 1500.0);  // absent: the default

  EXPECT_EQ(error_of("[safety]\noutput_max_V = 11\n"),
            "site.toml:2:16: safety.output_max_V: value 11 is not allowed: must be in (0, 10]");
  EXPECT_EQ(error_of("[safety]\nmax_consecutive_overruns = 0\n"),
            "site.toml:2:28: safety.max_consecutive_overruns: value 0 is not allowed: must be in "
            "[1, 1000000]");
  EXPECT_EQ(error_of("[safety]\nsafe_ramp_V_per_s = 2000\n"),
            "site.toml: safety.safe_ramp_V_per_s = 2000 must not exceed safety.max_slew_V_per_s "
            "= 1500");
  EXPECT_EQ(error_of("[safety]\nsgs_min_V = 10\n"),
            "site.toml: safety.sgs_min_V = 10 must be below safety.sgs_max_V = 10");
}

TEST(SafetyRanges, TheSupervisorRefusesWhatTheReaderRefuses) {
  SafetyLimits l;
  l.jump_factor = 1.5;  // below the 2 a second-order stage's overshoot needs
  SafetySupervisor s;
  try {
    s.configure(l, 1e-3, {});
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "SafetyLimits: safety.jump_factor = 1.5 must be in [2, 100]");
  }
}

}  // namespace
}  // namespace piezoshift::runtime
