#pragma once
// The plate's dominant mode from a recorded ring-down: samples x_k of a displacement taken at a
// fixed rate after a small step. A damped cosine on a constant obeys
//   x_k = a1 x_{k-1} + a2 x_{k-2} + c,   a1 = 2 r cos(theta), a2 = -r^2
// (Prony's method for one mode), so a least-squares fit of a1, a2, c gives the mode's angle per
// sample theta = acos(a1 / (2 sqrt(-a2))) and its frequency theta rate / (2 pi), folded into
// [0, rate / 2] like any sampled mode. The first samples after the step (where the step itself,
// not the ring, dominates) are left out.
#include <cstddef>
#include <span>

namespace piezoshift::calibration {

struct PlateModeEstimate {
  double mode_Hz = 0.0;    //!< folded into [0, sample_rate_Hz / 2]; 0 when none was found
  double theta_rad = 0.0;  //!< the mode's angle per sample
  double sample_rate_Hz = 0.0;
  //! Per-sample decay r (|pole|): below 1 for a damped mode; 0 when none was found.
  double pole_radius = 0.0;
};

//! Samples left out at the start of the record (the step's own transient).
inline constexpr std::size_t kModeSkipSamples = 3;

//! x: the ring-down, from the step on, at sample_rate_Hz. No oscillation in the record (fewer
//! than 9 samples, or a real pole pair) gives mode_Hz = 0: the caller then shapes for no mode.
PlateModeEstimate identify_plate_mode(std::span<const double> x_um, double sample_rate_Hz);

//! The frequency [Hz] of the ring-down's largest spectral peak between min_Hz and the Nyquist
//! frequency (the record after kModeSkipSamples, its mean and slope removed, a Hann window; 1 Hz
//! steps); 0 for a record too short. Where several modes ring (a fast record sees the piston
//! mode and the tilts, which a one-mode Prony fit blends), it picks the loudest: the piston
//! mode after a step of the three legs together.
double ring_peak_Hz(std::span<const double> x_um, double sample_rate_Hz, double min_Hz);

}  // namespace piezoshift::calibration
