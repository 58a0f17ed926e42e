#pragma once
// Repeatability, the paper's Eq. 9: the sample standard deviation of n displacements z_i
// recorded when the same move is repeated (Section 4.3: 230 moves to 5 um and to 10 um, 2 nm and
// 3 nm):
//   e_R = ( 1/(n-1) sum_i (z_i - zbar)^2 )^(1/2),   zbar = 1/n sum_i z_i.
// Computed in two passes (mean first), which keeps nm-level spreads of ~10 um values exact to
// rounding. At least 2 values, all finite; otherwise MetricsError.
#include <cstddef>
#include <span>

#include "piezoshift/experiments/metrics_error.hpp"

namespace piezoshift::experiments {

struct RepeatabilityMetrics {
  std::size_t n = 0;
  double mean_um = 0.0;           //!< zbar [um]
  double repeatability_um = 0.0;  //!< e_R [um]
  double repeatability_nm = 0.0;  //!< e_R [nm]
  double min_um = 0.0;
  double max_um = 0.0;
};

RepeatabilityMetrics repeatability_metrics(std::span<const double> measured_um);

}  // namespace piezoshift::experiments
