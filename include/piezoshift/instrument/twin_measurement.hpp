#pragma once
// A phase-shifting measurement of the twin, the parts every procedure that takes one composes the
// same way (`measure` and Python's measure() through procedures/measure_run.hpp, `reproduce`'s
// phase measurement, the twin's hold): the scene the twin camera renders, the analysis' options,
// the sequence on the simulated DAQ and clock, and the figures against the twin's truth.
#include <cstdint>
#include <string>

#include "piezoshift/camera/camera.hpp"
#include "piezoshift/camera/camera_config.hpp"
#include "piezoshift/camera/instrument_config.hpp"
#include "piezoshift/camera/twin_camera.hpp"
#include "piezoshift/instrument/acquisition.hpp"
#include "piezoshift/instrument/measurement.hpp"
#include "piezoshift/instrument/sequence.hpp"
#include "piezoshift/psi/analysis.hpp"
#include "piezoshift/psi/fizeau_simulation.hpp"

namespace piezoshift::instrument {

//! The twin camera's scene: surface on a pupil of 0.47 of the frame's side, drawn as `psi
//! simulate` draws it for the same spec and seed, rendered with the Fizeau's optics at
//! params.wavelength_nm.
camera::TwinScene measurement_scene(const psi::SurfaceSpec& surface, const camera::CameraConfig& cc,
                                    const SequenceParams& params, std::uint64_t seed);

//! The analysis of a measurement's frames: algorithm over the commanded steps, at the sequence's
//! wavelength.
psi::AnalysisOptions measurement_analysis_options(psi::Algorithm algorithm,
                                                  const SequenceParams& params);

//! The sequence on the twin (seed, the project's design and twin) at rate_Hz on a simulated clock,
//! as fast as the CPU allows; camera started. source: where the configuration came from, for
//! messages ("" built in).
SequenceResult acquire_on_simulated_twin(const config::ProjectConfig& project, std::uint64_t seed,
                                         double rate_Hz, const std::string& source,
                                         camera::Camera& camera, const LoopSetup& loop,
                                         const SequenceParams& params);

//! The measured surface against the scene's truth, and the same frames from an ideal stage (the
//! camera's and the algorithm's floor, one average); piston and tilt removed [nm RMS].
struct TwinErrors {
  double error_rms_nm = 0.0;
  double ideal_error_rms_nm = 0.0;
};
TwinErrors twin_errors(const camera::TwinScene& scene, const camera::CameraConfig& cc,
                       const SequenceParams& params, const MeasurementAnalysis& analysis,
                       const psi::AnalysisOptions& options);

}  // namespace piezoshift::instrument
