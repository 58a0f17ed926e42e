#pragma once
// The twin camera's floor: the frames of one average rendered again with the same noise draws
// (frame k from camera::frame_seed(seed, k), as the twin camera draws it) but from an ideal stage,
// exactly at the commanded steps and still during the exposure, and analysed the same way. The
// error of that surface is the camera's and the algorithm's; measured^2 - floor^2 is what the
// stage added (as `psi simulate` splits its error). The whole measurement's floor is the same
// for every exposure, frame after frame with its own frame's draws (its frame_id: a frame taken
// again draws anew), averaged as the measurement is.
#include "piezoshift/camera/camera_config.hpp"
#include "piezoshift/camera/twin_camera.hpp"
#include "piezoshift/instrument/sequence.hpp"
#include "piezoshift/psi/analysis.hpp"

namespace piezoshift::instrument {

//! RMS of (ideal-stage surface - truth) over the valid pixels, piston and tilt removed [nm].
double ideal_stage_error_rms_nm(const camera::TwinScene& scene, const camera::CameraConfig& cc,
                                const SequenceParams& params, const psi::AnalysisOptions& options);

//! The same over every exposure of a measurement and its averages (analyze_measurement).
double ideal_measurement_error_rms_nm(const camera::TwinScene& scene,
                                      const camera::CameraConfig& cc, const SequenceParams& params,
                                      const SequenceResult& measured,
                                      const psi::AnalysisOptions& options);

}  // namespace piezoshift::instrument
