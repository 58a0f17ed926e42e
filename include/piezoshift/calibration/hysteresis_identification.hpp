#pragma once
// Identification of the improved controller's channel model (control/hysteresis_creep_model.hpp)
// from a recorded open-loop run: the command u_k written at tick k and the gauge reading y_k read
// at tick k, per channel. With the thresholds and creep time constants fixed (evenly spread over
// the command's span and over the decades), the model is linear in its parameters once the
// operators and the creep terms are run on the record, so it is fitted by least squares:
//   1. y_k ~ offset + w0 u_{k-D} + sum_j w_j s_j(u)_{k-D}           (operators on u)
//   2. the creep regressor sum_m (c_m - h) run on stage 1's h, then all together again
// for each delay D in [0, max_delay_ticks], keeping the best. Weights that come out negative are
// dropped and the fit repeated (the model's inverse needs non-negative weights, and a negative
// weight only fits noise).
#include <cstddef>
#include <span>

#include "piezoshift/control/hysteresis_creep_model.hpp"

namespace piezoshift::calibration {

struct HysteresisFitOptions {
  std::size_t operators = 10;           //!< play operators over the span (at most 16)
  double command_span_um = 16.0;        //!< thresholds (j + 1/2) span / N
  double creep_shortest_s = 0.003;      //!< creep terms from here ...
  double creep_longest_s = 300.0;       //!< ... to here
  std::size_t creep_terms_per_decade = 2;
  std::size_t max_delay_ticks = 4;
  //! Samples this long after a command jump are left out: the amplifier's slew and the plate's
  //! ringing are dynamics the static model does not hold (the shaper and the loop handle them).
  double exclude_after_jump_s = 0.015;
  double jump_um = 0.02;  //!< a command change per tick larger than this is a jump
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
