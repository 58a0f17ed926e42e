#include "gcs_arguments.hpp"

#include <charconv>
#include <cmath>

namespace piezoshift::host::gcs {

// GCS framing: every line but the last ends with a space before the LF.
std::string framed(const std::vector<std::string>& lines) {
  std::string out;
  for (std::size_t i = 0; i < lines.size(); ++i)
    out += lines[i] + (i + 1 < lines.size() ? " \n" : "\n");
  return out;
}

bool parse_real(std::string_view s, double& value) {
  const char* end = s.data() + s.size();
  const auto r = std::from_chars(s.data(), end, value);
  return r.ec == std::errc{} && r.ptr == end && std::isfinite(value);
}

bool parse_integer(std::string_view s, long long& value) {
  int base = 10;
  if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
    s.remove_prefix(2);  // GCS writes bit masks and parameter ids in hex: 0x101, 0x16000200
    base = 16;
  }
  const char* end = s.data() + s.size();
  const auto r = std::from_chars(s.data(), end, value, base);
  return r.ec == std::errc{} && r.ptr == end;
}

int axis_of(std::string_view s) {
  for (Axis a : kAxes)
    if (s == axis_name(a))
      return static_cast<int>(a);
  return -1;
}

// "{axis} {value} ..." pairs; kNone on success.
GcsError parse_pairs(const std::vector<std::string_view>& args, std::vector<AxisValue>& out) {
  if (args.empty() || args.size() % 2 != 0)
    return GcsError::kParamCount;
  std::array<bool, 3> seen{};
  for (std::size_t i = 0; i < args.size(); i += 2) {
    const int axis = axis_of(args[i]);
    if (axis < 0)
      return GcsError::kInvalidAxis;
    if (seen[static_cast<std::size_t>(axis)])
      return GcsError::kDoubleAxis;
    seen[static_cast<std::size_t>(axis)] = true;
    double v = 0.0;
    if (!parse_real(args[i + 1], v))
      return GcsError::kInvalidReal;
    out.push_back(AxisValue{static_cast<std::size_t>(axis), v});
  }
  return GcsError::kNone;
}

// "[{axis} ...]", all axes when empty; kNone on success.
GcsError parse_axes(const std::vector<std::string_view>& args, std::vector<std::size_t>& out) {
  if (args.empty()) {
    out = {0, 1, 2};
    return GcsError::kNone;
  }
  if (args.size() > GcsInterpreter::kMaxQueryItems)
    return GcsError::kParamCount;
  for (std::string_view a : args) {
    const int axis = axis_of(a);
    if (axis < 0)
      return GcsError::kInvalidAxis;
    out.push_back(static_cast<std::size_t>(axis));
  }
  return GcsError::kNone;
}

// "[{n} ...]" integers in [1, max], all when empty; kNone on success.
GcsError parse_ids(const std::vector<std::string_view>& args, int max, std::vector<int>& out,
                   GcsError out_of_range) {
  if (args.empty()) {
    for (int i = 1; i <= max; ++i)
      out.push_back(i);
    return GcsError::kNone;
  }
  if (args.size() > GcsInterpreter::kMaxQueryItems)
    return GcsError::kParamCount;
  for (std::string_view a : args) {
    long long v = 0;
    if (!parse_integer(a, v))
      return GcsError::kParamSyntax;
    if (v < 1 || v > max)
      return out_of_range;
    out.push_back(static_cast<int>(v));
  }
  return GcsError::kNone;
}

// "{generator} {integer} ..." pairs with generators 1..n, each at most once (`WGO 1 1 1 0` says
// two things of one generator: refused as a syntax error, as a repeated axis is); kNone on
// success.
GcsError generator_pairs(const std::vector<std::string_view>& args, std::size_t n,
                         std::vector<WaveGenerators::Setting>& out) {
  if (args.empty() || args.size() % 2 != 0)
    return GcsError::kParamCount;
  for (std::size_t i = 0; i < args.size(); i += 2) {
    long long g = 0;
    long long v = 0;
    if (!parse_integer(args[i], g) || !parse_integer(args[i + 1], v))
      return GcsError::kParamSyntax;
    if (g < 1 || g > static_cast<long long>(n))
      return GcsError::kWaveIndex;
    const auto index = static_cast<std::size_t>(g - 1);
    for (const auto& [seen, value] : out) {
      if (seen == index)
        return GcsError::kParamSyntax;
    }
    out.emplace_back(index, v);
  }
  return GcsError::kNone;
}

}  // namespace piezoshift::host::gcs
