#pragma once
// The Fizeau's hold on the twin, composed from the instrument's pieces as
//
//   piezoshift measure --free-run --camera twin --daq sim --config C --calibration CAL
//                      --averages N --hold-s H [--lock] --seed S
//
// runs it (docs/measure.md, the CLI's defaults for every other option): the twin camera's scene
// (the default test surface drawn from S, the Fizeau's optics at 632.8 nm), the twin at the
// loop's rate on a simulated clock, hariharan5's five steps from Z_d = 5 um, N averages, then the
// stage held at frame 0 for H s of loop time while the camera exposes frame after frame; with the
// lock, the first average's first frames are its reference and every later frame feeds it. The
// twin's [safety] overrun rule "on hardware" is never on the twin, as `measure` resolves it.
// `compare --lock` runs it per seed and controller (docs/compare.md); the figures it returns are
// `measure --json`'s "hold" to the last digit.
#include <cstdint>

#include "piezoshift/calibration/loop_calibration.hpp"
#include "piezoshift/camera/instrument_config.hpp"
#include "piezoshift/instrument/hold_summary.hpp"
#include "piezoshift/instrument/sequence.hpp"

namespace piezoshift::instrument {

struct TwinHoldOptions {
  std::uint64_t seed = 1;   //!< the twin's and the scene's (measure --seed)
  int averages = 10;        //!< measurements before the hold, 1 to 100 (measure --averages)
  double hold_s = 60.0;     //!< loop time held at frame 0 [s], 0 to 3600 (measure --hold-s)
  bool lock = false;        //!< the fringe lock holds the cavity (measure --lock)
  double rate_Hz = 1000.0;  //!< the loop's (measure --rate-hz)
};

struct TwinHold {
  SequenceResult sequence;  //!< not valid with its reason when the run failed
  HoldSummary summary;      //!< hold_summary(sequence)
};

//! One run (see the header). config: the instrument's ([camera], [safety], the twin: with
//! twin.cavity.in_fringes the cavity's drift is in the fringes); calibration: the controller the
//! loop runs (its [fringe_lock] parameters, and its outer = "fringes" asking for the lock too).
//! Throws core::InputError for what `measure` refuses as bad input (the sequence's parameters,
//! the lock, a sequence beyond the calibrated travel).
TwinHold twin_hold(const camera::InstrumentConfig& config,
                   const calibration::LoopCalibration& calibration, const TwinHoldOptions& options);

}  // namespace piezoshift::instrument
