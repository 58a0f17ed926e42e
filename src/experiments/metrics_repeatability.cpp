#include "piezoshift/experiments/metrics_repeatability.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

namespace piezoshift::experiments {

RepeatabilityMetrics repeatability_metrics(std::span<const double> measured_um) {
  const std::size_t n = measured_um.size();
  if (n < 2) {
    throw MetricsError(
        fmt::format("repeatability: {} value{}; Eq. 9 needs at least 2 (it divides by n - 1)", n,
                    n == 1 ? "" : "s"));
  }
  RepeatabilityMetrics r;
  r.n = n;
  r.min_um = r.max_um = measured_um[0];
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double z = measured_um[i];
    if (!std::isfinite(z))
      throw MetricsError(fmt::format("repeatability: value {} is not finite", i));
    sum += z;
    r.min_um = std::min(r.min_um, z);
    r.max_um = std::max(r.max_um, z);
  }
  r.mean_um = sum / static_cast<double>(n);
  double ss = 0.0;
  for (const double z : measured_um)
    ss += (z - r.mean_um) * (z - r.mean_um);
  // Finite values can still overflow the sum or the squares (1e308 and -1e308): a failure, not
  // an infinite e_R.
  if (!std::isfinite(r.mean_um) || !std::isfinite(ss) ||
      !std::isfinite(1000.0 * (r.max_um - r.min_um)))
    throw MetricsError(fmt::format(
        "repeatability: the values (from {} to {} um) overflow Eq. 9 in double precision", r.min_um,
        r.max_um));
  r.repeatability_um = std::sqrt(ss / static_cast<double>(n - 1));
  r.repeatability_nm = 1000.0 * r.repeatability_um;
  return r;
}

}  // namespace piezoshift::experiments
