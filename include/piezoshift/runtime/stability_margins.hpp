#pragma once
// Gain and phase margins of a discrete loop L(e^{j 2 pi f T}), from its frequency response on a
// dense logarithmic grid up to the Nyquist frequency, each crossing refined by bisection:
//   phase crossover  the unwrapped phase of L crosses -180 deg (mod 360): gain margin
//                    -20 log10 |L| there, the smallest over all crossovers;
//   gain crossover   |L| crosses 1: phase margin 180 deg + arg L there (wrapped to (-180, 180]),
//                    the smallest over all crossovers.
// A margin with no crossover below Nyquist is +infinity (its frequency NaN). The margins say how
// far the loop is from instability; they do not by themselves say the closed loop is stable (an
// unstable open loop, or a Nyquist plot that encircles -1 twice, needs the full criterion), which
// for the loops piezoshift analyses (stable stacks, an integrating PID) they do.
//
// The PID's response is the incremental PID of control/incremental_pid.hpp (Eqs. 6 and 7):
//   C(z) = [kp (1 - z^-1) + ki + kd (1 - a) (1 - z^-1)^2 / (1 - a z^-1)] / (1 - z^-1)
// with the per-sample gains at the loop's sample time and a the derivative filter.
#include <complex>
#include <functional>

#include "piezoshift/control/incremental_pid.hpp"

namespace piezoshift::runtime {

struct StabilityMargins {
  double gain_margin_dB = 0.0;      //!< +inf when the phase never reaches -180 deg
  double phase_crossover_Hz = 0.0;  //!< where; NaN when none
  double phase_margin_deg = 0.0;    //!< +inf when |L| never crosses 1
  double gain_crossover_Hz = 0.0;   //!< where; NaN when none
};

//! C(e^{j 2 pi f T}) of the incremental PID with per-sample gains (already at sample_time_s).
std::complex<double> pid_frequency_response(const control::PidParams& pid, double frequency_Hz,
                                            double sample_time_s);

//! The margins of loop(f) between f_min_Hz (> 0) and f_max_Hz (at most Nyquist). Throws
//! std::invalid_argument when the band is empty or the loop's response is not finite on it.
StabilityMargins stability_margins(const std::function<std::complex<double>(double)>& loop,
                                   double f_min_Hz, double f_max_Hz);

}  // namespace piezoshift::runtime
