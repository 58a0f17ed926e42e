#include "piezoshift/experiments/metrics_step_response.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

namespace piezoshift::experiments {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// Instant where the straight line between samples (ta, ga) and (tb, gb) reaches level.
double crossing(double ta, double ga, double tb, double gb, double level) {
  if (gb == ga)
    return tb;
  return ta + (tb - ta) * (level - ga) / (gb - ga);
}

// Refuses a record the metrics cannot be read from, and options out of range.
void check_record(std::span<const double> t_s, std::span<const double> y_um,
                  const StepResponseOptions& o) {
  const std::size_t n = t_s.size();
  if (y_um.size() != n) {
    throw MetricsError(
        fmt::format("step response: {} time values but {} displacements", n, y_um.size()));
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(t_s[i]) || !std::isfinite(y_um[i]))
      throw MetricsError(fmt::format("step response: sample {} has a non-finite value", i));
    if (i > 0 && !(t_s[i] > t_s[i - 1]))
      throw MetricsError(
          fmt::format("step response: time must increase strictly (sample {}: {} s after {} s)", i,
                      t_s[i], t_s[i - 1]));
  }
  if (!(o.final_window_fraction > 0.0 && o.final_window_fraction <= 1.0))
    throw MetricsError("step response: final_window_fraction must be in (0, 1]");
  if (!(o.band_pct > 0.0) || !(o.band_nm > 0.0) || !std::isfinite(o.band_pct) ||
      !std::isfinite(o.band_nm))
    throw MetricsError("step response: the settling bands must be > 0");
  if (!std::isfinite(o.step_time_s))
    throw MetricsError(
        fmt::format("step response: step_time_s = {} must be finite", o.step_time_s));
}

// Index of the first sample at or after the step instant; at least 3 samples must follow.
std::size_t first_sample_after_step(std::span<const double> t_s, double step_time_s) {
  const std::size_t n = t_s.size();
  const auto first_after =
      static_cast<std::size_t>(std::lower_bound(t_s.begin(), t_s.end(), step_time_s) - t_s.begin());
  if (n - first_after < 3) {
    throw MetricsError(fmt::format(
        "step response: {} samples at or after the step instant {} s; at least 3 are needed",
        n - first_after, step_time_s));
  }
  return first_after;
}

// y0: given, or the mean of the samples before the step (the first sample if there are none).
double initial_level_um(std::span<const double> y_um, std::size_t first_after,
                        const StepResponseOptions& o) {
  if (!std::isnan(o.initial_um))
    return o.initial_um;
  if (first_after == 0)
    return y_um[0];
  double s = 0.0;
  for (std::size_t i = 0; i < first_after; ++i)
    s += y_um[i];
  return s / static_cast<double>(first_after);
}

// y_inf: given, or the mean of the last final_window_fraction of the samples.
double final_level_um(std::span<const double> y_um, const StepResponseOptions& o) {
  if (!std::isnan(o.final_um))
    return o.final_um;
  const std::size_t n = y_um.size();
  const auto count = std::max<std::size_t>(
      1, static_cast<std::size_t>(std::ceil(o.final_window_fraction * static_cast<double>(n))));
  double s = 0.0;
  for (std::size_t i = n - count; i < n; ++i)
    s += y_um[i];
  return s / static_cast<double>(count);
}

// Rise time: first 10 % crossing at or after t_s, then the first 90 % crossing after it, on the
// filtered record y.
void set_rise_time(StepResponseMetrics& m, std::span<const double> t_s,
                   const std::vector<double>& y, std::size_t first_after) {
  const std::size_t n = t_s.size();
  auto g = [&](std::size_t i) { return (y[i] - m.initial_um) / m.step_um; };
  m.t10_s = m.t90_s = m.rise_time_s = kNaN;
  std::size_t i10 = n;
  for (std::size_t i = first_after; i < n; ++i) {
    if (g(i) >= 0.1) {
      i10 = i;
      m.t10_s = (i > first_after) ? crossing(t_s[i - 1], g(i - 1), t_s[i], g(i), 0.1) : t_s[i];
      break;
    }
  }
  for (std::size_t i = i10; i < n; ++i) {
    if (g(i) >= 0.9) {
      m.t90_s = (i > i10) ? crossing(t_s[i - 1], g(i - 1), t_s[i], g(i), 0.9) : t_s[i];
      break;
    }
  }
  m.rise_time_s = m.t90_s - m.t10_s;
}

// Peak in the direction of the step, from the raw samples: a median clips a sampled peak.
void set_peak(StepResponseMetrics& m, std::span<const double> t_s, std::span<const double> y_um,
              std::size_t first_after) {
  auto g_raw = [&](std::size_t i) { return (y_um[i] - m.initial_um) / m.step_um; };
  std::size_t ipk = first_after;
  for (std::size_t i = first_after; i < y_um.size(); ++i) {
    if (g_raw(i) > g_raw(ipk))
      ipk = i;
  }
  m.peak_um = y_um[ipk];
  m.peak_time_s = t_s[ipk];
  m.overshoot_pct = 100.0 * std::max(0.0, g_raw(ipk) - 1.0);
}

// Settling: last sample of the filtered record y outside final_um +- half_width_um, then the
// instant the record re-enters the band, from the step instant.
double settling_time_s(std::span<const double> t_s, const std::vector<double>& y, double final_um,
                       std::size_t first_after, double step_time_s, double half_width_um) {
  const std::size_t n = t_s.size();
  std::size_t last_out = n;
  for (std::size_t i = n; i-- > first_after;) {
    if (std::abs(y[i] - final_um) > half_width_um) {
      last_out = i;
      break;
    }
  }
  if (last_out == n)
    return 0.0;
  if (last_out == n - 1)
    return kInf;
  const double edge = final_um + (y[last_out] > final_um ? half_width_um : -half_width_um);
  return crossing(t_s[last_out], y[last_out], t_s[last_out + 1], y[last_out + 1], edge) -
         step_time_s;
}

}  // namespace

std::vector<double> running_median(std::span<const double> y, std::size_t window) {
  if (window == 0 || window % 2 == 0 || window > kMaxMedianWindow)
    throw MetricsError(fmt::format("running median: window {} must be odd and in [1, {}]", window,
                                   kMaxMedianWindow));
  const std::size_t n = y.size();
  std::vector<double> out(y.begin(), y.end());
  if (window == 1)
    return out;
  const std::size_t half = window / 2;
  std::vector<double> buf;
  buf.reserve(std::min(window, n));
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t h = std::min({half, i, n - 1 - i});  // symmetric at the ends
    buf.assign(y.begin() + static_cast<std::ptrdiff_t>(i - h),
               y.begin() + static_cast<std::ptrdiff_t>(i + h + 1));
    std::nth_element(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(h), buf.end());
    out[i] = buf[h];
  }
  return out;
}

StepResponseMetrics step_response_metrics(std::span<const double> t_s, std::span<const double> y_um,
                                          const StepResponseOptions& o) {
  check_record(t_s, y_um, o);
  const std::size_t first_after = first_sample_after_step(t_s, o.step_time_s);

  StepResponseMetrics m;
  m.band_pct = o.band_pct;
  m.band_nm = o.band_nm;
  m.initial_um = initial_level_um(y_um, first_after, o);
  m.final_um = final_level_um(y_um, o);
  if (!std::isfinite(m.initial_um) || !std::isfinite(m.final_um))
    throw MetricsError("step response: the initial and final levels must be finite");
  m.step_um = m.final_um - m.initial_um;
  if (m.step_um == 0.0)
    throw MetricsError("step response: the step (final - initial level) is 0");

  const std::vector<double> y = running_median(y_um, o.median_window);
  set_rise_time(m, t_s, y, first_after);
  set_peak(m, t_s, y_um, first_after);
  m.settling_time_pct_s = settling_time_s(t_s, y, m.final_um, first_after, o.step_time_s,
                                          o.band_pct / 100.0 * std::abs(m.step_um));
  m.settling_time_abs_s =
      settling_time_s(t_s, y, m.final_um, first_after, o.step_time_s, o.band_nm / 1000.0);
  return m;
}

}  // namespace piezoshift::experiments
