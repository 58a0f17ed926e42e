#pragma once
// Set-point shaping of the improved controller, per channel: a rate limit (the amplifier's slew
// limit expressed in SGS um per tick, so the command never asks for more than the amplifier can
// deliver) followed by a short FIR input shaper with positive taps summing to 1 that puts zeros on
// the plate's lightly damped mode, so a step excites no ringing:
//
//   q(k) = q(k-1) + clamp(target - q(k-1), +-rate)        rate limit
//   r(k) = sum_i taps_i q(k - i)                           shaper (unit DC gain)
//
// design_mode_shaper() picks the taps for a mode at f_Hz sampled at T: with theta = 2 pi f T
// folded to [0, pi] (what the loop sees of a mode above Nyquist: the taps' zeros are on the unit
// circle, where an alias and its mode are the same), three taps (1, -2 cos theta, 1) / (2 - 2 cos
// theta) when cos theta <= 0 (all positive: no overshoot), else a moving average of round(2 pi /
// theta) taps (its first zero at the mode). At 1 kHz the paper's 1.42 kHz plate mode folds to
// 0.42 kHz: taps (0.27, 0.47, 0.27); at 10 kHz, a 7-tap moving average.
//
// Real-time safe: no heap, no exceptions, no I/O; fixed sizes; every member noexcept.
#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>

namespace piezoshift::control {

inline constexpr std::size_t kMaxShaperTaps = 16;

template <class T>
struct BasicShaperParams {
  std::size_t taps = 1;
  std::array<T, kMaxShaperTaps> weight{T(1)};  //!< taps_0 .. taps_{n-1}, sum 1
  T rate_um_per_s = T(1e9);                    //!< the rate limit (SGS um/s)
};

using ShaperParams = BasicShaperParams<double>;

template <class To, class From>
constexpr BasicShaperParams<To> convert(const BasicShaperParams<From>& p) noexcept {
  BasicShaperParams<To> q{};
  q.taps = p.taps;
  for (std::size_t i = 0; i < kMaxShaperTaps; ++i)
    q.weight[i] = static_cast<To>(p.weight[i]);
  q.rate_um_per_s = static_cast<To>(p.rate_um_per_s);
  return q;
}

//! The taps for a mode at mode_Hz sampled at sample_time_s (see the header comment); a single tap
//! (no shaping) when the mode is not positive or its moving average would be too long.
template <class T>
BasicShaperParams<T> design_mode_shaper(T mode_Hz, T sample_time_s, T rate_um_per_s) noexcept {
  BasicShaperParams<T> p{};
  p.rate_um_per_s = rate_um_per_s;
  if (!(mode_Hz > T(0)) || !(sample_time_s > T(0)))
    return p;
  const T two_pi = T(2) * std::numbers::pi_v<T>;
  T theta = std::fmod(two_pi * mode_Hz * sample_time_s, two_pi);
  if (theta > std::numbers::pi_v<T>)
    theta = two_pi - theta;
  const T c = std::cos(theta);
  if (c <= T(0)) {
    const T sum = T(2) - T(2) * c;
    p.taps = 3;
    p.weight = {};
    p.weight[0] = p.weight[2] = T(1) / sum;
    p.weight[1] = -T(2) * c / sum;
    return p;
  }
  const T n = std::round(two_pi / theta);
  if (!(n >= T(1)) || n > T(kMaxShaperTaps))
    return p;
  p.taps = static_cast<std::size_t>(n);
  p.weight = {};
  for (std::size_t i = 0; i < p.taps; ++i)
    p.weight[i] = T(1) / n;
  return p;
}

template <class T>
class BasicSetpointShaper {
 public:
  constexpr void configure(const BasicShaperParams<T>& params, T sample_time_s) noexcept {
    p_ = params;
    if (p_.taps < 1 || p_.taps > kMaxShaperTaps)
      p_.taps = 1;
    rate_per_tick_ = p_.rate_um_per_s * sample_time_s;
    reset(T(0));
  }
  //! Holds value: the shaper's output is value until the target moves.
  constexpr void reset(T value) noexcept {
    q_.fill(value);
    out_ = value;
  }
  constexpr T update(T target) noexcept {
    T d = target - q_[0];
    if (!(d == d))
      d = T(0);
    d = d > rate_per_tick_ ? rate_per_tick_ : (d < -rate_per_tick_ ? -rate_per_tick_ : d);
    for (std::size_t i = p_.taps - 1; i > 0; --i)
      q_[i] = q_[i - 1];
    q_[0] += d;
    T r = T(0);
    for (std::size_t i = 0; i < p_.taps; ++i)
      r += p_.weight[i] * q_[i];
    out_ = r;
    return r;
  }
  constexpr T output() const noexcept { return out_; }
  //! How far target is from the rate limiter's present value.
  constexpr T distance(T target) const noexcept {
    const T d = target - q_[0];
    return d < T(0) ? -d : d;
  }

 private:
  BasicShaperParams<T> p_{};
  std::array<T, kMaxShaperTaps> q_{};
  T rate_per_tick_ = T(1e9);
  T out_ = T(0);
};

using SetpointShaper = BasicSetpointShaper<double>;

}  // namespace piezoshift::control
