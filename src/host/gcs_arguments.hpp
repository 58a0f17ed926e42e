#pragma once
// The GCS interpreter's argument parsing and answer framing, shared by its command groups
// (gcs_interpreter.cpp and gcs_*.cpp); private to the host module.
#include <array>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/core.h>

#include "piezoshift/host/gcs_error.hpp"
#include "piezoshift/host/gcs_interpreter.hpp"
#include "piezoshift/host/stage_model.hpp"
#include "piezoshift/host/wave_generators.hpp"

namespace piezoshift::host::gcs {

// One pair of an "{axis} {value} ..." list.
struct AxisValue {
  std::size_t axis;
  double value;
};

// GCS framing: every line but the last ends with a space before the LF.
std::string framed(const std::vector<std::string>& lines);

// A finite real, the whole token.
bool parse_real(std::string_view s, double& value);

// A decimal integer, or a hexadecimal one with 0x (bit masks, parameter ids), the whole token.
bool parse_integer(std::string_view s, long long& value);

// The index of axis name s (Z, U, V), -1 for another name.
int axis_of(std::string_view s);

// "{axis} {value} ..." pairs; kNone on success.
GcsError parse_pairs(const std::vector<std::string_view>& args, std::vector<AxisValue>& out);

// "[{axis} ...]", all axes when empty; kNone on success.
GcsError parse_axes(const std::vector<std::string_view>& args, std::vector<std::size_t>& out);

// "[{n} ...]" integers in [1, max], all when empty; kNone on success.
GcsError parse_ids(const std::vector<std::string_view>& args, int max, std::vector<int>& out,
                   GcsError out_of_range);

// One "key=value" line per requested axis (all when none), or the parse error.
template <typename Value>
GcsError axis_lines(const std::vector<std::string_view>& args, Value value, std::string& answer) {
  std::vector<std::size_t> axes;
  if (const GcsError e = parse_axes(args, axes); e != GcsError::kNone)
    return e;
  std::vector<std::string> lines;
  for (std::size_t a : axes)
    lines.push_back(fmt::format("{}={}", axis_name(kAxes[a]), value(a)));
  answer = framed(lines);
  return GcsError::kNone;
}

// One "n=value" line per requested channel or table in [1, max] (all when none).
template <typename Value>
GcsError id_lines(const std::vector<std::string_view>& args, int max, GcsError out_of_range,
                  Value value, std::string& answer) {
  std::vector<int> ids;
  if (const GcsError e = parse_ids(args, max, ids, out_of_range); e != GcsError::kNone)
    return e;
  std::vector<std::string> lines;
  for (int id : ids)
    lines.push_back(fmt::format("{}={}", id, value(id)));
  answer = framed(lines);
  return GcsError::kNone;
}

// A "Z=..." line's value: v[a] with `digits` decimals.
inline auto fixed(const AxisValues& v, int digits) {
  return [&v, digits](std::size_t a) { return fmt::format("{:.{}f}", v[a], digits); };
}

// One "g=value" line per requested wave generator (1-based; all when none); value(g) 0-based.
template <typename Value>
GcsError generator_lines(const std::vector<std::string_view>& args, Value value,
                         std::string& answer) {
  const auto of = [&value](int g) { return value(static_cast<std::size_t>(g - 1)); };
  return id_lines(args, static_cast<int>(WaveGenerators::kGenerators), GcsError::kWaveIndex, of,
                  answer);
}

// "{generator} {integer} ..." pairs with generators 1..n, each at most once (`WGO 1 1 1 0` says
// two things of one generator: refused as a syntax error, as a repeated axis is); kNone on
// success.
GcsError generator_pairs(const std::vector<std::string_view>& args, std::size_t n,
                         std::vector<WaveGenerators::Setting>& out);

}  // namespace piezoshift::host::gcs
