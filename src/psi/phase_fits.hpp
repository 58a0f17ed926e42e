#pragma once
// The iterative fits of phase_algorithms.hpp, AIA and tilt-aware AIA (Algorithm::kAia, kTiltAia),
// which find the steps (and the tilt-aware one each frame's shift plane) from the frames
// themselves and check their own result (docs/psi.md, "Fits that check themselves"). Private to
// the psi module: wrapped_phase() is their entry point.
#include <cmath>
#include <cstddef>
#include <numbers>
#include <span>
#include <vector>

#include "piezoshift/psi/phase_algorithms.hpp"

namespace piezoshift::psi::detail {

constexpr double kPi = std::numbers::pi;

//! a wrapped into [-pi, pi].
inline double wrap(double a) {
  return std::remainder(a, 2.0 * kPi);
}

//! n steps 0, step, 2 step, ...
inline std::vector<double> uniform_steps(int n, double step) {
  std::vector<double> d(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k)
    d[static_cast<std::size_t>(k)] = k * step;
  return d;
}

//! Fits phase, modulation, steps (and shifts, kTiltAia) of the pupil pixels pix into r, which
//! holds NaN maps of mask's size; r.reason says why the fit is not to be trusted ("" when it is).
void fit_phase(std::span<const Map> frames, const Mask& mask, const std::vector<std::size_t>& pix,
               const PhaseOptions& o, PhaseResult& r);

}  // namespace piezoshift::psi::detail
