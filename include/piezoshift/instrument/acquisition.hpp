#pragma once
// One measurement's acquisition on any DAQ backend and clock: the loop built in owner mode
// around the backend (control_loop.hpp), the backend activated, the sequence run
// (sequence.hpp), the outputs at 0 V again whatever happened. `piezoshift measure` calls it with
// its loop stack (real-time or free-running, the twin or a board); Python with the twin on a
// simulated clock.
#include <atomic>

#include "piezoshift/camera/camera.hpp"
#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/instrument/sequence.hpp"
#include "piezoshift/runtime/daq_backend.hpp"
#include "piezoshift/runtime/loop_clock.hpp"
#include "piezoshift/runtime/safety_supervisor.hpp"

namespace piezoshift::instrument {

struct LoopSetup {
  control::SemiClosedLoopParams controller;  //!< the calibration
  runtime::SafetyLimits limits{};
  double rate_Hz = 1000.0;
  const std::atomic<int>* stop_signal = nullptr;  //!< SIGINT/SIGTERM: the sequence stops
};

//! The camera must be started; the backend configured, not active. twin: the twin's plate for
//! the twin camera and the records (nullptr on hardware).
SequenceResult acquire_sequence(runtime::DaqBackend& daq, runtime::LoopClock& clock,
                                const plant::Twin* twin, camera::Camera& camera,
                                const LoopSetup& loop, const SequenceParams& params,
                                const rig::Progress& progress = {});

}  // namespace piezoshift::instrument
