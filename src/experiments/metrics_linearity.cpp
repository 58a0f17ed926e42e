#include "piezoshift/experiments/metrics_linearity.hpp"

#include <cmath>

#include <fmt/core.h>

namespace piezoshift::experiments {

LinearityMetrics linearity_metrics(std::span<const double> desired_um,
                                   std::span<const double> measured_um) {
  if (desired_um.size() != measured_um.size()) {
    throw MetricsError(fmt::format("linearity: {} desired values but {} measured",
                                   desired_um.size(), measured_um.size()));
  }
  const std::size_t n = desired_um.size();
  if (n < kLinearityMinPoints) {
    throw MetricsError(fmt::format(
        "linearity: {} point{}; at least {} are needed (a line through 2 points fits them "
        "exactly)",
        n, n == 1 ? "" : "s", kLinearityMinPoints));
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(desired_um[i]) || !std::isfinite(measured_um[i]))
      throw MetricsError(fmt::format("linearity: point {} has a non-finite value", i));
  }
  const double x0 = desired_um.front(), x1 = desired_um.back();
  const double y0 = measured_um.front(), y1 = measured_um.back();
  if (x0 == x1) {
    throw MetricsError(fmt::format(
        "linearity: the first and last desired_um are equal ({}); the sweep must span a range",
        x0));
  }
  LinearityMetrics m;
  m.n = n;
  m.span_um = y1 - y0;
  if (m.span_um == 0.0) {
    throw MetricsError(fmt::format(
        "linearity: the measured span (last - first measured_um) is 0; it is the base of the "
        "percentage"));
  }
  m.zero_end_slope = (y1 - y0) / (x1 - x0);
  m.zero_end_intercept_um = y0 - m.zero_end_slope * x0;

  double xbar = 0.0, ybar = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    xbar += desired_um[i];
    ybar += measured_um[i];
  }
  xbar /= static_cast<double>(n);
  ybar /= static_cast<double>(n);
  double sxx = 0.0, sxy = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    sxx += (desired_um[i] - xbar) * (desired_um[i] - xbar);
    sxy += (desired_um[i] - xbar) * (measured_um[i] - ybar);
  }
  // sxx > 0 because x0 != x1.
  m.best_fit_slope = sxy / sxx;
  m.best_fit_intercept_um = ybar - m.best_fit_slope * xbar;

  m.deviation_zero_end_um.resize(n);
  m.deviation_best_fit_um.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double x = desired_um[i];
    const double y = measured_um[i];
    // Zero-end deviation measured from the first point so that it is exactly 0 at both ends.
    m.deviation_zero_end_um[i] = (y - y0) - m.zero_end_slope * (x - x0);
    m.deviation_best_fit_um[i] = (y - ybar) - m.best_fit_slope * (x - xbar);
    m.max_deviation_zero_end_um =
        std::max(m.max_deviation_zero_end_um, std::abs(m.deviation_zero_end_um[i]));
    m.max_deviation_best_fit_um =
        std::max(m.max_deviation_best_fit_um, std::abs(m.deviation_best_fit_um[i]));
  }
  m.linearity_zero_end_pct = 100.0 * m.max_deviation_zero_end_um / std::abs(m.span_um);
  m.linearity_best_fit_pct = 100.0 * m.max_deviation_best_fit_um / std::abs(m.span_um);
  // Finite points can still overflow the sums and products (1e308): a failure, never a NaN.
  bool finite = std::isfinite(m.best_fit_slope) && std::isfinite(m.best_fit_intercept_um) &&
                std::isfinite(m.zero_end_slope) && std::isfinite(m.zero_end_intercept_um) &&
                std::isfinite(m.linearity_zero_end_pct) && std::isfinite(m.linearity_best_fit_pct);
  for (std::size_t i = 0; i < n; ++i)
    finite = finite && std::isfinite(m.deviation_zero_end_um[i]) &&
             std::isfinite(m.deviation_best_fit_um[i]);
  if (!finite)
    throw MetricsError("linearity: the values overflow the fits in double precision");
  return m;
}

}  // namespace piezoshift::experiments
