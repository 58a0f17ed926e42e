#pragma once
// A check for integer options, run on the option's text before CLI11 converts it. CLI11 converts
// with strtoll/strtoull and keeps what they return: 2^64 became INT64_MAX and -1 became 2^64 - 1
// for an unsigned option, both in silence (--seed -1 ran as seed 2^64 - 1, --max-overruns 2^64 as
// INT64_MAX). Here the text must be a whole number within [lo, hi], else CLI11 reports the option
// and exit status is 2.
#include <charconv>
#include <cstdint>
#include <limits>
#include <string>

#include <fmt/core.h>
#include <CLI/CLI.hpp>

namespace piezoshift::app {

inline constexpr std::uint64_t kAnyUnsigned = std::numeric_limits<std::uint64_t>::max();

inline CLI::Validator whole_number(std::int64_t lo, std::uint64_t hi) {
  // 2^64 - 1 rather than its 20 digits, which read as a made-up limit in --help.
  const std::string range = hi == kAnyUnsigned ? fmt::format("a whole number in [{}, 2^64 - 1]", lo)
                                               : fmt::format("a whole number in [{}, {}]", lo, hi);
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        const char* first = text.data();
        const char* last = text.data() + text.size();
        bool ok = false;
        if (!text.empty() && text[0] == '-') {
          std::int64_t v = 0;
          const auto r = std::from_chars(first, last, v);
          ok = r.ec == std::errc() && r.ptr == last && v >= lo;
        } else {
          std::uint64_t v = 0;
          const auto r = std::from_chars(first, last, v);
          ok = r.ec == std::errc() && r.ptr == last && v <= hi &&
               (lo <= 0 || v >= static_cast<std::uint64_t>(lo));
        }
        return ok ? std::string() : fmt::format("{} is not {}", text, range);
      },
      range);
}

}  // namespace piezoshift::app
