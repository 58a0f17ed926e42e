#include "piezoshift/plant/flicker.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace piezoshift::plant {
namespace {

std::size_t term_count(double tau_min, double tau_max, std::int64_t per_decade) {
  if (!(tau_min > 0.0) || !(tau_max >= tau_min) || !std::isfinite(tau_max))
    throw std::invalid_argument("flicker: need 0 < shortest time constant <= longest");
  if (per_decade < 1)
    throw std::invalid_argument("flicker: terms per decade must be >= 1");
  const double count =
      std::floor(std::log10(tau_max / tau_min) * static_cast<double>(per_decade) + 1e-9) + 1.0;
  if (count > static_cast<double>(kMaxFlickerTerms))
    throw std::invalid_argument("flicker: " + std::to_string(static_cast<long long>(count)) +
                                " terms, more than " + std::to_string(kMaxFlickerTerms));
  return static_cast<std::size_t>(count);
}

// Variance of the mean over a window of r time constants of a unit-variance OU process.
double window_mean_variance(double r) {
  if (r < 1e-6)
    return 1.0 - r / 3.0;
  return 2.0 / r * (1.0 - (1.0 - std::exp(-r)) / r);
}

}  // namespace

FlickerNoise::FlickerNoise(double psd_at_1Hz, double tau_min, double tau_max,
                           std::int64_t per_decade, double update_period_s) {
  if (!(psd_at_1Hz >= 0.0) || !std::isfinite(psd_at_1Hz))
    throw std::invalid_argument("flicker: the 1/f level must be >= 0");
  if (!(update_period_s > 0.0))
    throw std::invalid_argument("flicker: the update period must be positive");
  n_ = term_count(tau_min, tau_max, per_decade);
  const double per = static_cast<double>(per_decade);
  v_ = psd_at_1Hz * std::numbers::ln10 / per;
  for (std::size_t k = 0; k < n_; ++k) {
    tau_[k] = tau_min * std::pow(10.0, static_cast<double>(k) / per);
    const double s = std::fmax(1.0, std::floor(tau_[k] / (100.0 * update_period_s)));
    stride_[k] = static_cast<std::uint64_t>(s);
    decay_[k] = std::exp(-s * update_period_s / tau_[k]);
    drive_[k] = std::sqrt(v_ * (1.0 - decay_[k] * decay_[k]));
  }
}

void FlickerNoise::start(FlickerState& x, Rng& rng) const noexcept {
  const double sd = std::sqrt(v_);
  for (std::size_t k = 0; k < n_; ++k)
    x[k] = sd * rng.normal();
}

double FlickerNoise::psd(double f_Hz) const noexcept {
  double s = 0.0;
  for (std::size_t k = 0; k < n_; ++k) {
    const double wt = 2.0 * std::numbers::pi * f_Hz * tau_[k];
    s += 4.0 * v_ * tau_[k] / (1.0 + wt * wt);
  }
  return s;
}

double FlickerNoise::window_variance(double window_s) const noexcept {
  double s = 0.0;
  for (std::size_t k = 0; k < n_; ++k)
    s += v_ * (1.0 - window_mean_variance(window_s / tau_[k]));
  return s;
}

double flicker_psd_for_window_rms(double sigma, double window_s, double tau_min, double tau_max,
                                  std::int64_t per_decade) {
  if (!(window_s > 0.0) || !std::isfinite(window_s))
    throw std::invalid_argument("flicker: the window must be positive");
  const FlickerNoise unit(1.0, tau_min, tau_max, per_decade, 1.0);
  return sigma * sigma / unit.window_variance(window_s);
}

}  // namespace piezoshift::plant
