#pragma once
// A second-order notch on a sampled signal, unit gain at DC (compare's oracle takes the
// plate's lightly damped mode out of its feedback where its ring test finds the PID rings there):
//
//   H(z) = g (1 - 2 cos(theta) z^-1 + z^-2) / (1 - 2 r cos(theta) z^-1 + r^2 z^-2)
//   theta = 2 pi f T folded to [0, pi] (a mode above Nyquist is seen at its alias, so the notch
//           goes where the loop sees it),  g = (1 - 2 r cos(theta) + r^2) / (2 - 2 cos(theta))
//
// r < 1 sets the width: about (1 - r) / (pi T) Hz between the -3 dB points. The zeros sit on the
// unit circle, so the folded frequency is removed exactly. A notch at 0 Hz would remove DC and is
// refused (mode_Hz that folds to within a bin of 0 gives no notch: passes through).
//
// Real-time safe: no heap, no exceptions, no I/O.
#include <array>
#include <cmath>
#include <cstddef>
#include <numbers>

namespace piezoshift::control {

struct NotchParams {
  double mode_Hz = 0.0;       //!< the frequency removed (folded at the sample rate); 0 = none
  double pole_radius = 0.85;  //!< r: closer to 1 is narrower
  bool operator==(const NotchParams&) const = default;
};

//! compare's oracle takes out at most this many modes (in series); unused ones are mode_Hz 0.
inline constexpr std::size_t kMaxOracleNotches = 2;
using OracleNotches = std::array<NotchParams, kMaxOracleNotches>;

class NotchFilter {
 public:
  NotchFilter() = default;
  NotchFilter(const NotchParams& p, double sample_time_s) noexcept {
    const double two_pi = 2.0 * std::numbers::pi;
    double theta = std::fmod(two_pi * p.mode_Hz * sample_time_s, two_pi);
    if (theta > std::numbers::pi)
      theta = two_pi - theta;
    const double c = std::cos(theta);
    if (!(p.mode_Hz > 0.0) || !(sample_time_s > 0.0) || !(2.0 - 2.0 * c > 1e-6) ||
        !(p.pole_radius >= 0.0 && p.pole_radius < 1.0))
      return;  // no notch: passes through
    const double r = p.pole_radius;
    const double g = (1.0 - 2.0 * r * c + r * r) / (2.0 - 2.0 * c);
    b_ = {g, -2.0 * c * g, g};
    a1_ = -2.0 * r * c;
    a2_ = r * r;
    active_ = true;
  }

  bool active() const noexcept { return active_; }

  //! One sample. The first one starts the filter at rest on it (no transient from 0).
  double update(double x) noexcept {
    if (!active_)
      return x;
    if (!started_) {
      x1_ = x2_ = y1_ = y2_ = x;
      started_ = true;
    }
    const double y = b_[0] * x + b_[1] * x1_ + b_[2] * x2_ - a1_ * y1_ - a2_ * y2_;
    x2_ = x1_;
    x1_ = x;
    y2_ = y1_;
    y1_ = y;
    return y;
  }

 private:
  bool active_ = false, started_ = false;
  std::array<double, 3> b_{1.0, 0.0, 0.0};
  double a1_ = 0.0, a2_ = 0.0;
  double x1_ = 0.0, x2_ = 0.0, y1_ = 0.0, y2_ = 0.0;
};

}  // namespace piezoshift::control
