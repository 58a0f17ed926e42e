#include "piezoshift/plant/creep.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace piezoshift::plant {

CreepChain::CreepChain(const CreepParams& p, double update_period_s) {
  if (!(p.per_decade_fraction >= 0.0) || !std::isfinite(p.per_decade_fraction))
    throw std::invalid_argument("creep: per_decade_fraction must be >= 0");
  if (!(p.shortest_time_constant_s > 0.0) ||
      !(p.longest_time_constant_s >= p.shortest_time_constant_s) ||
      !std::isfinite(p.longest_time_constant_s))
    throw std::invalid_argument("creep: need 0 < shortest_time_constant_s <= longest");
  if (p.terms_per_decade < 1)
    throw std::invalid_argument("creep: terms_per_decade must be >= 1");
  if (!(update_period_s > 0.0))
    throw std::invalid_argument("creep: the update period must be positive");
  const double decades = std::log10(p.longest_time_constant_s / p.shortest_time_constant_s);
  const double per = static_cast<double>(p.terms_per_decade);
  const double count = std::floor(decades * per + 1e-9) + 1.0;
  if (count > static_cast<double>(kMaxCreepTerms)) {
    throw std::invalid_argument("creep: " + std::to_string(static_cast<long long>(count)) +
                                " terms, more than " + std::to_string(kMaxCreepTerms));
  }
  n_ = static_cast<std::size_t>(count);
  a_ = p.per_decade_fraction / per;
  for (std::size_t k = 0; k < n_; ++k) {
    tau_[k] = p.shortest_time_constant_s * std::pow(10.0, static_cast<double>(k) / per);
    decay_[k] = std::exp(-update_period_s / tau_[k]);
    gain_[k] = (1.0 - decay_[k]) * a_;
  }
}

double CreepChain::step_response(double t_s) const noexcept {
  double s = 0.0;
  for (std::size_t k = 0; k < n_; ++k)
    s += 1.0 - std::exp(-t_s / tau_[k]);
  return a_ * s;
}

}  // namespace piezoshift::plant
