#include "piezoshift/calibration/mode_identification.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

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

double ring_peak_Hz(std::span<const double> x, double sample_rate_Hz, double min_Hz) {
  if (x.size() < kModeSkipSamples + 16 || !(sample_rate_Hz > 0.0))
    return 0.0;
  const std::span<const double> ring = x.subspan(kModeSkipSamples);
  const auto n = static_cast<double>(ring.size());
  // Least-squares line through the record, removed so the slow return is not a peak.
  double st = 0.0, sx = 0.0, stt = 0.0, stx = 0.0;
  for (std::size_t k = 0; k < ring.size(); ++k) {
    const auto t = static_cast<double>(k);
    st += t;
    sx += ring[k];
    stt += t * t;
    stx += t * ring[k];
  }
  const double slope = (n * stx - st * sx) / (n * stt - st * st);
  const double offset = (sx - slope * st) / n;
  std::vector<double> y(ring.size());
  for (std::size_t k = 0; k < ring.size(); ++k) {
    const auto t = static_cast<double>(k);
    const double hann = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * t / (n - 1.0));
    y[k] = hann * (ring[k] - offset - slope * t);
  }
  double best_Hz = 0.0, best_power = 0.0;
  for (double f = std::max(min_Hz, 1.0); f < 0.5 * sample_rate_Hz; f += 1.0) {
    const double w = 2.0 * std::numbers::pi * f / sample_rate_Hz;
    double re = 0.0, im = 0.0;
    for (std::size_t k = 0; k < y.size(); ++k) {
      re += y[k] * std::cos(w * static_cast<double>(k));
      im -= y[k] * std::sin(w * static_cast<double>(k));
    }
    const double power = re * re + im * im;
    if (power > best_power) {
      best_power = power;
      best_Hz = f;
    }
  }
  return best_Hz;
}

}  // namespace piezoshift::calibration
