#pragma once
// Linearity of a displacement sweep (paper, Section 4.2: 0 to 11 um in 1 um steps, 0.21 % by
// the zero-end-point method). Points (x_i, y_i), i = 0..n-1: x desired, y measured [um].
//
//   base      B = y_{n-1} - y_0                     (the measured span, first to last point)
//   zero-end  line through the first and last points:
//               L0(x) = y_0 + (y_{n-1} - y_0) (x - x_0) / (x_{n-1} - x_0)
//             d0_i = y_i - L0(x_i);   linearity_zero_end_pct = 100 max_i |d0_i| / |B|
//   best-fit  least-squares line L1(x) = a + b x, b = Sxy / Sxx, a = ybar - b xbar
//             (Sxy = sum (x_i - xbar)(y_i - ybar), Sxx = sum (x_i - xbar)^2):
//             d1_i = y_i - L1(x_i);   linearity_best_fit_pct = 100 max_i |d1_i| / |B|
// Both use the same base B so the two percentages compare directly. (The least-squares line
// minimises the sum of squared deviations, not the largest one, so its percentage is usually but
// not always the smaller.)
//
// At least 3 points (with two, both lines pass through every point and say nothing), x_0 !=
// x_{n-1}, B != 0, all finite; otherwise MetricsError.
#include <cstddef>
#include <span>
#include <vector>

#include "piezoshift/experiments/metrics_error.hpp"

namespace piezoshift::experiments {

struct LinearityMetrics {
  std::size_t n = 0;
  double span_um = 0.0;                //!< B = y_{n-1} - y_0 [um]
  double zero_end_slope = 0.0;         //!< of L0 [um/um]
  double zero_end_intercept_um = 0.0;  //!< L0(0) [um]
  double best_fit_slope = 0.0;         //!< b [um/um]
  double best_fit_intercept_um = 0.0;  //!< a [um]
  double max_deviation_zero_end_um = 0.0;
  double max_deviation_best_fit_um = 0.0;
  double linearity_zero_end_pct = 0.0;
  double linearity_best_fit_pct = 0.0;
  std::vector<double> deviation_zero_end_um;  //!< d0_i, one per point
  std::vector<double> deviation_best_fit_um;  //!< d1_i, one per point
};

inline constexpr std::size_t kLinearityMinPoints = 3;

LinearityMetrics linearity_metrics(std::span<const double> desired_um,
                                   std::span<const double> measured_um);

}  // namespace piezoshift::experiments
