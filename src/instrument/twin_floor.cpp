#include "piezoshift/instrument/twin_floor.hpp"

#include <algorithm>
#include <cmath>
#include <span>

#include "piezoshift/instrument/measurement.hpp"
#include "piezoshift/plant/random.hpp"
#include "piezoshift/psi/fizeau_simulation.hpp"

namespace piezoshift::instrument {

namespace {

// Frame `frame_id`'s noise draws, from a still stage at piston_nm, as the twin camera counts.
psi::Map still_frame(const camera::TwinScene& scene, const camera::CameraConfig& cc,
                     double piston_nm, std::uint64_t frame_id) {
  const psi::CameraParams sensor = camera::sensor_params(cc);
  const double gain = std::pow(10.0, cc.settings.gain_dB / 20.0);
  const double top = std::ldexp(1.0, sensor.bit_depth) - 1.0;
  const psi::PoseSample still{0.0, piston_nm, 0.0, 0.0};
  plant::Rng rng(camera::frame_seed(scene.seed, frame_id));
  psi::Map f = psi::render_frame(scene.surface_nm, scene.mask, scene.fizeau, sensor,
                                 std::span<const psi::PoseSample>(&still, 1), rng);
  for (double& v : f.v)
    v = std::min(top, std::round(v * gain));  // the twin camera's digital gain
  return f;
}

}  // namespace

double ideal_stage_error_rms_nm(const camera::TwinScene& scene, const camera::CameraConfig& cc,
                                const SequenceParams& params, const psi::AnalysisOptions& options) {
  std::vector<psi::Map> frames;
  for (std::size_t k = 0; k < params.steps_rad.size(); ++k)
    frames.push_back(still_frame(scene, cc, step_piston_nm(params, k), k));
  const psi::Analysis a = psi::analyze_frames(frames, scene.mask, options);
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
    const psi::Map m = still_frame(scene, cc, e.commanded_piston_nm, e.frame_id);
    camera::Frame f;
    f.frame_id = e.frame_id;
    f.width_px = m.width;
    f.height_px = m.height;
    f.counts.resize(m.size());
    std::transform(m.v.begin(), m.v.end(), f.counts.begin(),
                   [](double v) { return static_cast<std::uint16_t>(v); });
    ideal.frames.push_back(std::move(f));
  }
  const MeasurementAnalysis a = analyze_measurement(ideal, params, scene.mask, options);
  return psi::surface_error_rms_nm(a.surface_nm, scene.surface_nm, a.valid);
}

}  // namespace piezoshift::instrument
