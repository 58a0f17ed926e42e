#include "piezoshift/instrument/twin_floor.hpp"

#include <span>
#include <vector>

#include "piezoshift/instrument/measurement.hpp"
#include "piezoshift/psi/fizeau_simulation.hpp"

namespace piezoshift::instrument {

namespace {

// Frame `frame_id`'s noise draws, from a still stage at piston_nm, as the twin camera counts.
camera::Frame still_frame(const camera::TwinScene& scene, const camera::CameraConfig& cc,
                          double piston_nm, std::uint64_t frame_id) {
  const psi::PoseSample still{0.0, piston_nm, 0.0, 0.0};
  camera::Frame f;
  f.frame_id = frame_id;
  f.width_px = scene.surface_nm.width;
  f.height_px = scene.surface_nm.height;
  camera::render_twin_counts(scene, camera::sensor_params(cc), cc.settings.gain_dB,
                             std::span<const psi::PoseSample>(&still, 1), frame_id, f.counts);
  return f;
}

}  // namespace

double ideal_stage_error_rms_nm(const camera::TwinScene& scene, const camera::CameraConfig& cc,
                                const SequenceParams& params, const psi::AnalysisOptions& options) {
  std::vector<camera::Frame> frames;
  for (std::size_t k = 0; k < params.steps_rad.size(); ++k)
    frames.push_back(still_frame(scene, cc, step_piston_nm(params, k), k));
  const psi::Analysis a = psi::analyze_frames(frame_maps(frames), scene.mask, options);
  return psi::surface_error_rms_nm(a.surface_nm, scene.surface_nm, a.valid);
}

double ideal_measurement_error_rms_nm(const camera::TwinScene& scene,
                                      const camera::CameraConfig& cc, const SequenceParams& params,
                                      const SequenceResult& measured,
                                      const psi::AnalysisOptions& options) {
  SequenceResult ideal;
  ideal.exposures = measured.exposures;
  for (ExposureRecord& e : ideal.exposures) {
    e.has_truth = false;  // the steps' check has nothing to compare with: not needed here
    ideal.frames.push_back(still_frame(scene, cc, e.commanded_piston_nm, e.frame_id));
  }
  const MeasurementAnalysis a = analyze_measurement(ideal, params, scene.mask, options);
  return psi::surface_error_rms_nm(a.surface_nm, scene.surface_nm, a.valid);
}

}  // namespace piezoshift::instrument
