#include "piezoshift/calibration/mode_identification.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>

namespace piezoshift::calibration {

PlateModeEstimate identify_plate_mode(std::span<const double> x, double sample_rate_Hz) {
  PlateModeEstimate out;
  out.sample_rate_Hz = sample_rate_Hz;
  if (x.size() < kModeSkipSamples + 6 || !(sample_rate_Hz > 0.0))
    return out;
  const auto rows = static_cast<Eigen::Index>(x.size() - kModeSkipSamples);
  Eigen::MatrixXd X(rows, 3);
  Eigen::VectorXd y(rows);
  for (Eigen::Index k = 0; k < rows; ++k) {
    const auto j = static_cast<std::size_t>(k) + kModeSkipSamples;
    X(k, 0) = x[j - 1];
    X(k, 1) = x[j - 2];
    X(k, 2) = 1.0;
    y(k) = x[j];
  }
  const Eigen::Vector3d a = X.colPivHouseholderQr().solve(y);
  // a2 = -r^2 < 0 and a complex pair (|a1| < 2 r): an oscillation. A real pair is no mode.
  if (!(a(1) < 0.0))
    return out;
  const double r = std::sqrt(-a(1));
  const double c = a(0) / (2.0 * r);
  if (!(std::fabs(c) < 1.0))
    return out;
  out.theta_rad = std::acos(c);
  out.mode_Hz = out.theta_rad * sample_rate_Hz / (2.0 * std::numbers::pi);
  out.pole_radius = r;
  return out;
}

}  // namespace piezoshift::calibration
