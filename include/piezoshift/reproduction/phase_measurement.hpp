#pragma once
// The reproduction's phase-shifting measurement: what the stage is for, taken through the same
// library path as `piezoshift measure --camera twin` (docs/measure.md):
//   a fresh twin session (runtime::SimBackend, seed + 100) on a simulated clock, the controller
//   `reproduce` calibrated, a camera::TwinCamera of make_twin_scene(the default SurfaceSpec,
//   a 256 x 256 px Fizeau, pupil 0.47 of the side, 632.8 nm) with the default [camera]
//   (camera::CameraConfig{}), Hariharan's 5 frames, 1 average;
//   instrument::acquire_sequence, instrument::analyze_measurement, and the ideal-stage floor
//   (instrument::ideal_stage_error_rms_nm: the same noise draws from a perfect stage).
// Not valid when the sequence is not (a step that did not settle, a fault, a frame lost) or a fit
// did not converge; the reason says which. Deterministic: the twin camera's noise depends on
// (seed, frame) alone and a simulated clock waits for each frame.
#include <cstdint>
#include <limits>
#include <string>

#include "piezoshift/camera/camera_config.hpp"
#include "piezoshift/camera/twin_camera.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/instrument/measurement.hpp"
#include "piezoshift/instrument/sequence.hpp"
#include "piezoshift/rig/validity.hpp"
#include "piezoshift/runtime/safety_supervisor.hpp"

namespace piezoshift::reproduction {

//! The seed offset of the measurement's twin session and scene (after the inner loop's + 90, + 91).
inline constexpr std::uint64_t kMeasurementSeedOffset = 100;

struct PhaseMeasurement {
  std::string algorithm;  //!< psi's name ("hariharan5")
  instrument::SequenceParams params;
  camera::CameraConfig camera;
  camera::TwinScene scene;  //!< the truth and the optics
  instrument::SequenceResult sequence;
  instrument::MeasurementAnalysis analysis;  //!< empty when the sequence is not valid
  //! measured - true and the ideal stage's, RMS with piston and tilt removed [nm]; NaN when
  //! there is no measured surface.
  double error_rms_nm = std::numeric_limits<double>::quiet_NaN();
  double ideal_error_rms_nm = std::numeric_limits<double>::quiet_NaN();
  double simulated_time_s = 0.0;  //!< the session's ticks, servo on to 0 V
  rig::Validity validity;
};

//! One measurement on a fresh twin session (seed: the session's and the scene's), supervised
//! with limits.
PhaseMeasurement run_phase_measurement(const config::ProjectConfig& config,
                                       const control::SemiClosedLoopParams& controller,
                                       std::uint64_t seed,
                                       const runtime::SafetyLimits& limits = {});

}  // namespace piezoshift::reproduction
