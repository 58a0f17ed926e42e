#pragma once
// Flicker (1/f) noise for the real-time loop: a sum of first-order Gauss-Markov processes whose
// time constants span decades (Keshner 1982; Kasdin 1995, "Discrete simulation of colored noise
// and stochastic processes and 1/f^alpha power law noise generation", Section III: a log-uniform
// spread of relaxation rates with equal variances gives a 1/f spectrum between the corners).
//
// Terms k = 0..K-1, tau_k = tau_min 10^(k / n), n per decade, up to tau_max; each an
// Ornstein-Uhlenbeck process of variance v (one-sided PSD 4 v tau / (1 + (2 pi f tau)^2)):
//   x_k <- e_k x_k + sqrt(v (1 - e_k^2)) N(0, 1),   e_k = exp(-s_k T / tau_k)   (exact)
// updated every s_k control periods T, s_k = max(1, floor(tau_k / (100 T))): a slow term moves
// less than 15 % of its rms between updates, so holding it costs nothing visible and spares
// most of the deviates. Output x = sum_k x_k. Integrating the Lorentzians over log tau,
//   S(f) = A / f  for 1 / (2 pi tau_max) << f << 1 / (2 pi tau_min),   v = A ln(10) / n.
// The expected sample variance of x over a window of length W (what a repeatability run of
// that duration sees; continuous sampling) is
//   E[s^2] = sum_k v (1 - g(W / tau_k)),   g(r) = (2 / r) (1 - (1 - e^-r) / r)
// (g is the variance of the window mean of a unit OU process). The state starts drawn from the
// stationary distribution, so a run's first second is like any other.
//
// Real-time safe (update): no heap, no exceptions, no I/O.
#include <array>
#include <cstddef>
#include <cstdint>

#include "piezoshift/plant/random.hpp"

namespace piezoshift::plant {

inline constexpr std::size_t kMaxFlickerTerms = 16;

using FlickerState = std::array<double, kMaxFlickerTerms>;

class FlickerNoise {
 public:
  FlickerNoise() = default;
  //! A = psd_at_1Hz (units^2 / Hz); the band tau_min..tau_max, n terms per decade; T the update
  //! period. Throws std::invalid_argument for an empty band or more than kMaxFlickerTerms terms.
  FlickerNoise(double psd_at_1Hz, double shortest_time_constant_s, double longest_time_constant_s,
               std::int64_t terms_per_decade, double update_period_s);

  //! Draws the state from the stationary distribution (terms in index order).
  void start(FlickerState& x, Rng& rng) const noexcept;
  //! One control period (tick = the period's index, which picks the terms due); returns x.
  double update(FlickerState& x, std::uint64_t tick, Rng& rng) const noexcept {
    double sum = 0.0;
    for (std::size_t k = 0; k < n_; ++k) {
      if (tick % stride_[k] == 0)
        x[k] = decay_[k] * x[k] + drive_[k] * rng.normal();
      sum += x[k];
    }
    return sum;
  }
  //! x without updating.
  double output(const FlickerState& x) const noexcept {
    double sum = 0.0;
    for (std::size_t k = 0; k < n_; ++k)
      sum += x[k];
    return sum;
  }

  //! The model's one-sided PSD sum_k 4 v tau_k / (1 + (2 pi f tau_k)^2) [units^2 / Hz].
  double psd(double f_Hz) const noexcept;
  //! E[s^2] over a window of W seconds (above) [units^2].
  double window_variance(double window_s) const noexcept;
  //! The stationary variance K v [units^2].
  double variance() const noexcept { return static_cast<double>(n_) * v_; }
  std::size_t terms() const noexcept { return n_; }
  double time_constant_s(std::size_t k) const noexcept { return tau_[k]; }

 private:
  std::size_t n_ = 0;
  double v_ = 0.0;
  std::array<double, kMaxFlickerTerms> tau_{};
  std::array<double, kMaxFlickerTerms> decay_{};
  std::array<double, kMaxFlickerTerms> drive_{};
  std::array<std::uint64_t, kMaxFlickerTerms> stride_{};
};

//! A for which a flicker process with the given band has an expected sample variance of
//! sigma^2 over a window of W seconds (the inverse of window_variance, which is linear in A).
double flicker_psd_for_window_rms(double sigma, double window_s, double shortest_time_constant_s,
                                  double longest_time_constant_s, std::int64_t terms_per_decade);

}  // namespace piezoshift::plant
