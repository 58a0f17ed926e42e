#include "piezoshift/instrument/acquisition.hpp"

#include <limits>

#include "piezoshift/runtime/control_loop.hpp"
#include "piezoshift/runtime/setpoint_profile.hpp"

namespace piezoshift::instrument {

SequenceResult acquire_sequence(runtime::DaqBackend& daq, runtime::LoopClock& clock,
                                const plant::Twin* twin, camera::Camera& camera,
                                const LoopSetup& setup, const SequenceParams& params,
                                const rig::Progress& progress) {
  runtime::LoopConfig lc;
  lc.rate_Hz = setup.rate_Hz;
  lc.duration_s = std::numeric_limits<double>::infinity();
  lc.stop_signal = setup.stop_signal;
  lc.owner_drives = true;
  runtime::ControlLoop loop(lc, setup.controller, setup.limits, daq, clock,
                            runtime::SetpointProfile::step(0.0));
  daq.activate();
  SequenceResult r;
  try {
    r = run_sequence(loop, twin, camera, params, progress);
  } catch (...) {
    daq.deactivate();
    throw;
  }
  daq.deactivate();
  return r;
}

}  // namespace piezoshift::instrument
