#pragma once
// The improved calibration's verdict on its loop's rate: whether the plate's mode, as the loop
// samples it, makes the lambda/8 step slow there, and which rate would not.
//
// The shaper (control/setpoint_shaper.hpp) nulls the mode folded at the loop's rate: three taps
// when the fold is above a quarter of the rate, else a moving average over the fold's period.
// The step then takes the loop's delay D plus the taps' span, in ticks (measured at 1 kHz:
// 4 ms with 3 taps on the default twin, 7 and 6 ms with 6 and 5 taps on a 1175 and a 1190 Hz
// plate). A mode near a multiple of the rate folds near 0 Hz: a moving average over its period
// would exceed the shaper's 16 taps, and positive taps that null it span at least
// ceil(pi / theta) ticks (theta the fold per tick), so the step takes at least D + that (a
// 1024 Hz plate at 1 kHz: 23 ms; measured, unshaped, 37 ms). At a rate faster than the 1 ms
// exposures the step is judged on, one exposure is added (measured at 10 kHz: 1.6 to 1.8 ms
// against D + span = 0.8 ms).
//
// The mode must be the plate's own, unfolded: the calibration identifies it with the
// interferometer's dynamic samples at 10 kHz (an XL-80 samples up to 50 kHz), beside the
// loop-rate record the shaper is designed from.
#include <string>
#include <vector>

namespace piezoshift::calibration {

//! The lambda/8 step's settling the shaper allows [s] for a plate mode at mode_Hz, the loop at
//! rate_Hz with a delay of delay_ticks (above); infinity when the mode sits on a multiple of the
//! rate; NaN without a mode.
double shaped_phase_step_s(double mode_Hz, double rate_Hz, int delay_ticks);

//! The rates tried for a faster loop: these multiples of the loop's rate (each divides the
//! twin's 20 kHz physics rate for a 1 kHz loop).
inline constexpr int kRateMultiples[] = {2, 4, 5, 10};

struct RateVerdict {
  //! The mode makes the step at the loop's rate slower than target_s: the verdict names it.
  bool mode_is_the_limit = false;
  double mode_Hz = 0.0;         //!< the plate's mode, unfolded; 0 when none was identified
  double loop_rate_Hz = 0.0;    //!< the loop's rate
  double folded_Hz = 0.0;       //!< the mode as the loop samples it
  double step_s = 0.0;          //!< the step the shaper allows at the loop's rate
  double target_s = 0.0;        //!< the step's bound at the loop's rate
  double faster_rate_Hz = 0.0;  //!< the slowest tried rate whose step meets target_s; 0 none
  double faster_step_s = 0.0;   //!< its step
  //! One sentence for a summary: the mode, the step it allows here, the rate that meets the
  //! target; "" when the mode is not the limit.
  std::string text() const;
};

//! The verdict for a mode (unfolded, Hz; 0: none identified, no verdict) at loop_rate_Hz.
RateVerdict judge_loop_rate(double mode_Hz, double loop_rate_Hz, int delay_ticks,
                            double target_s = 5e-3);

}  // namespace piezoshift::calibration
