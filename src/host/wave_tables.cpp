#include "piezoshift/host/wave_tables.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numbers>

namespace piezoshift::host {

namespace {

bool real(std::string_view s, double& v) {
  const char* end = s.data() + s.size();
  const auto r = std::from_chars(s.data(), end, v);
  return r.ec == std::errc{} && r.ptr == end && std::isfinite(v);
}

bool integer(std::string_view s, long long& v) {
  const char* end = s.data() + s.size();
  const auto r = std::from_chars(s.data(), end, v);
  return r.ec == std::errc{} && r.ptr == end;
}

// The common numbers of LIN and SIN_P: seg amp off len start last.
struct Curve {
  long long seg = 0;
  double amp = 0.0;
  double off = 0.0;
  long long len = 0;
  long long start = 0;
  long long last = 0;  // LIN: speed-up/down points; SIN_P: curve centre point
};

GcsError parse_curve(const std::vector<std::string_view>& a, Curve& c) {
  if (a.size() != 8)
    return GcsError::kWaveParamCount;
  if (!integer(a[2], c.seg) || !real(a[3], c.amp) || !real(a[4], c.off) || !integer(a[5], c.len) ||
      !integer(a[6], c.start) || !integer(a[7], c.last))
    return GcsError::kParamSyntax;
  if (c.seg < 1 || c.seg > static_cast<long long>(WaveTables::kPoints))
    return GcsError::kWaveTooLong;
  if (c.len < 1 || c.len > c.seg || c.start < 0 || c.start >= c.seg || c.last < 0)
    return GcsError::kWaveParamOutOfRange;
  return GcsError::kNone;
}

std::vector<double> line(const Curve& c) {
  // Trapezoidal slope: the parabolic blends over `sud` points at each end meet a straight middle.
  const auto n = static_cast<double>(c.len);
  const double sud = static_cast<double>(c.last);
  const double v = c.amp / (n - sud);  // slope of the middle part, per point
  const auto at = [&](double i) {
    if (sud <= 0.0)
      return c.amp * i / n;
    if (i < sud)
      return v * i * i / (2.0 * sud);
    if (i > n - sud) {
      const double r = n - i;
      return c.amp - v * r * r / (2.0 * sud);
    }
    return v * (i - sud / 2.0);
  };
  std::vector<double> out(static_cast<std::size_t>(c.seg));
  for (long long j = 0; j < c.seg; ++j) {
    const long long i = j - c.start;
    const double x = i < 0 ? 0.0 : i >= c.len ? c.amp : at(static_cast<double>(i));
    out[static_cast<std::size_t>(j)] = c.off + x;
  }
  return out;
}

std::vector<double> inverted_cosine(const Curve& c) {
  const double pi = std::numbers::pi;
  std::vector<double> out(static_cast<std::size_t>(c.seg));
  for (long long j = 0; j < c.seg; ++j) {
    const long long i = ((j - c.start) % c.len + c.len) % c.len;
    double x = 0.0;
    if (i < c.last)
      x = (1.0 - std::cos(pi * static_cast<double>(i) / static_cast<double>(c.last))) / 2.0;
    else
      x = (1.0 +
           std::cos(pi * static_cast<double>(i - c.last) / static_cast<double>(c.len - c.last))) /
          2.0;
    out[static_cast<std::size_t>(j)] = c.off + c.amp * x;
  }
  return out;
}

}  // namespace

GcsError WaveTables::define(int table, const std::vector<std::string_view>& a) {
  if (!exists(table))
    return GcsError::kWaveIndex;
  if (a.size() < 2)
    return GcsError::kParamCount;
  const std::string_view mode = a[0];
  if (mode != "X" && mode != "&" && mode != "+")
    return GcsError::kParamSyntax;
  const std::string_view type = a[1];
  std::vector<double>& t = tables_[static_cast<std::size_t>(table - 1)];

  std::vector<double> segment;
  std::size_t at = 0;  // where PNT writes, 0-based
  if (type == "PNT") {
    long long start = 0;
    long long n = 0;
    if (a.size() < 4)
      return GcsError::kWaveParamCount;
    if (!integer(a[2], start) || !integer(a[3], n))
      return GcsError::kParamSyntax;
    if (n < 1 || static_cast<std::size_t>(n) != a.size() - 4)
      return GcsError::kWaveParamCount;
    // X takes the segment from its first point; & appends it, named by 1 (its own first point:
    // older PIPython's writewavepoints) or by the table's next point (newer ones send
    // `WAV 1 & PNT 21 20 ...` after 20 points); + adds from any point of the table.
    const bool appends_at_end = start == 1 || static_cast<std::size_t>(start) == t.size() + 1;
    if (start < 1 || (mode == "X" && start != 1) || (mode == "&" && !appends_at_end) ||
        static_cast<std::size_t>(start) > kPoints)
      return GcsError::kWaveParamOutOfRange;
    segment.resize(static_cast<std::size_t>(n));
    for (long long i = 0; i < n; ++i)
      if (!real(a[static_cast<std::size_t>(4 + i)], segment[static_cast<std::size_t>(i)]))
        return GcsError::kInvalidReal;
    at = mode == "&" ? t.size() : static_cast<std::size_t>(start - 1);
  } else if (type == "LIN" || type == "SIN_P") {
    Curve c;
    if (const GcsError e = parse_curve(a, c); e != GcsError::kNone)
      return e;
    if (type == "LIN" && 2 * c.last > c.len)
      return GcsError::kWaveParamOutOfRange;
    if (type == "SIN_P" && c.last > c.len)
      return GcsError::kWaveParamOutOfRange;
    segment = type == "LIN" ? line(c) : inverted_cosine(c);
    at = mode == "&" ? t.size() : 0;
  } else {
    return GcsError::kWaveTypeNotSupported;
  }

  if (at + segment.size() > kPoints)
    return GcsError::kWaveTooLong;
  if (mode == "X")
    t.clear();
  if (mode == "+") {
    if (t.size() < at + segment.size())
      t.resize(at + segment.size(), 0.0);
    for (std::size_t i = 0; i < segment.size(); ++i)
      t[at + i] += segment[i];
  } else {
    if (t.size() < at + segment.size())
      t.resize(at + segment.size());
    std::copy(segment.begin(), segment.end(), t.begin() + static_cast<std::ptrdiff_t>(at));
  }
  return GcsError::kNone;
}

}  // namespace piezoshift::host
