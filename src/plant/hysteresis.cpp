#include "piezoshift/plant/hysteresis.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace piezoshift::plant {

PrandtlIshlinskii::PrandtlIshlinskii(const HysteresisParams& params, double input_span_V) {
  const std::int64_t n = params.play_operators;
  if (n < 1 || n > static_cast<std::int64_t>(kMaxPlayOperators)) {
    throw std::invalid_argument("hysteresis: play_operators must be in [1, " +
                                std::to_string(kMaxPlayOperators) + "]");
  }
  if (!(input_span_V > 0.0) || !std::isfinite(input_span_V))
    throw std::invalid_argument("hysteresis: the input span must be positive");
  n_ = static_cast<std::size_t>(n);
  inv_span_ = 1.0 / input_span_V;
  double m1 = 0.0, mh = 0.0;
  for (std::size_t j = 0; j < n_; ++j) {
    rho_[j] = (static_cast<double>(j) + 0.5) / static_cast<double>(n_);
    m1 += std::fmin(rho_[j], 1.0 - rho_[j]);
    mh += 1.0 - rho_[j];
  }
  m1 /= static_cast<double>(n_);
  mh /= static_cast<double>(n_);
  const double h = params.hysteresis_fraction;
  if (!(h >= 0.0 && h < m1 / mh)) {
    throw std::invalid_argument("hysteresis: hysteresis_fraction must be in [0, " +
                                std::to_string(m1 / mh) + ")");
  }
  const double ratio = h / (m1 - h * mh);  // W / w0
  w0_ = 1.0 / (1.0 + ratio * mh);
  const double w = ratio * w0_ / static_cast<double>(n_);
  for (std::size_t j = 0; j < n_; ++j)
    w_[j] = w;
}

}  // namespace piezoshift::plant
