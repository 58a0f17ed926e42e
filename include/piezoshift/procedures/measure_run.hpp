#pragma once
// Runs one phase-shifting measurement (measure_request.hpp) through the shipping loop: the stage
// steps through the algorithm's sequence, the camera exposes once the stage has settled, then the
// analysis. `piezoshift measure` and Python's measure() both run it; neither composes a
// measurement of its own.
#include "piezoshift/procedures/measure_outcome.hpp"
#include "piezoshift/procedures/measure_request.hpp"
#include "piezoshift/rig/progress.hpp"

namespace piezoshift::procedures {

//! What differs between the front ends while it runs.
struct MeasureHooks {
  rig::Progress progress;        //!< the sequence's progress (the CLI's bar)
  bool stop_on_signals = false;  //!< SIGINT/SIGTERM end the sequence through the loop's ramp
};

//! Checks the request (validate), then, in this order so that bad input is named before anything
//! runs: the configuration, the sequence, its memory, the stack (DAQ), the calibration, the lock,
//! the travel, the camera (core::InputError naming the option or file at fault). Then the
//! sequence and its analysis. A measurement that is not valid or did not converge is an outcome
//! (MeasureOutcome::end), not an exception; the DAQ's outputs are at 0 V whatever happens.
MeasureOutcome run_measure(const MeasureRequest& request, const MeasureHooks& hooks = {});

}  // namespace piezoshift::procedures
