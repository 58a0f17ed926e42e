#pragma once
// Identification of the improved controller's channel model (control/hysteresis_creep_model.hpp)
// from a recorded open-loop run: the command u_k written at tick k and the gauge reading y_k read
// at tick k, per channel. With the thresholds and creep time constants fixed (evenly spread over
// the command's span, the grid's phase the best of a few, and over the decades), the model is
// linear in its parameters once the operators and the creep terms are run on the record, so it is
// fitted by least squares:
//   1. y_k ~ offset + w0 u_{k-D} + sum_j w_j s_j(u)_{k-D}           (operators on u)
//   2. the creep regressor sum_m (c_m - h) run on the last fit's h, then all together again;
//      optionally repeated until the creep gain settles (the creep term is bilinear in the
//      weights and the gain: each pass is exact given the previous h; the passes converge for
//      a small gain)
// for each delay D in [0, max_delay_ticks], keeping the best. Weights that come out negative are
// dropped and the fit repeated (the model's inverse needs non-negative weights, and a negative
// weight only fits noise).
#include <cstddef>
#include <span>

#include "piezoshift/control/hysteresis_creep_model.hpp"

namespace piezoshift::calibration {

struct HysteresisFitOptions {
  std::size_t operators = 16;     //!< play operators over the span (at most 16)
  double command_span_um = 16.0;  //!< thresholds (j + phase) span / N
  //! Grid phases tried, the best residual kept: 1/2 (centred), then on by 1/n of a spacing,
  //! wrapped into (0, 1] (2: 1/2 and 1; costs a fit per candidate). Where a stack's thresholds
  //! sit is not known beforehand; a grid half a spacing off them leaves the small-step slope
  //! after a move a few % wrong. Over seeds 1 to 8 of the default twin (thresholds at odd
  //! microns), 2 instead of 1 took the lambda/8 step's median settling at 10 kHz from 5.1 to
  //! 3.7 ms (seeds 5 and 6: 13 -> 2.6 ms, 43 -> 24 ms) and changed no other median.
  std::size_t threshold_phase_candidates = 2;
  double creep_shortest_s = 0.003;  //!< creep terms from here ...
  double creep_longest_s = 300.0;   //!< ... to here
  std::size_t creep_terms_per_decade = 2;
  //! The shortest creep term tried at creep_shortest_s and at this many steps of one term above
  //! it, the best fit kept (1: creep_shortest_s only; the search costs a fit per candidate).
  std::size_t creep_start_candidates = 1;
  std::size_t max_delay_ticks = 4;
  //! Step 2's passes at most, stopping early when the gain moves less than the tolerance.
  //! Iterated, the passes converge on the true model (exact on a record the model made,
  //! ChannelModelFit.*). With the grid's phase identified, over seeds 1 to 8 of the default twin
  //! 20 instead of 1 took the lambda/8 step's median settling from 6.5 to 4.0 ms at 1 kHz and
  //! from 3.7 to 1.6 ms at 10 kHz, and the 11 um step to +-10 nm from 61 to 29 ms (one pass
  //! leaves the small-step slope a few % off; measured before the phase was identified, the
  //! passes had made the phase step slower, docs/calibration.md).
  std::size_t max_creep_passes = 20;
  double creep_gain_tolerance = 1e-7;
  //! Samples this long after a command jump are left out: the amplifier's slew and the plate's
  //! ringing are dynamics the static model does not hold (the shaper and the loop handle them).
  double exclude_after_jump_s = 0.015;
  //! A command change per tick larger than this is a jump. At 1 kHz it keeps the excitation's
  //! 16 um/s ramps (0.016 um per tick) and leaves out its 20 um/s ramp to the top with the steps
  //! (kept, that ramp raised channel 2's residual from 5.3 to 7.1 nm on the default twin). It
  //! stays away from 0.02: there the rounding of the command (a CSV's last digit) decided row by
  //! row, and a fit from the recorded file differed from the twin's by 5e-6 in w0.
  double jump_um = 0.018;
};

struct HysteresisFit {
  control::HysteresisCreepParams params;
  std::size_t delay_ticks = 0;   //!< D: y_k answers u_{k-D}
  double rms_residual_um = 0.0;  //!< of the fit's prediction of y over the samples fitted
  std::size_t samples_fitted = 0;
  std::size_t operators_dropped = 0;
};

//! Throws FitError when the series differ in length, hold a non-finite value or are too short.
HysteresisFit fit_hysteresis_creep(std::span<const double> command_um,
                                   std::span<const double> gauge_um, double sample_time_s,
                                   const HysteresisFitOptions& options = {});

}  // namespace piezoshift::calibration
