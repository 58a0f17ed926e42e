#include "piezoshift/instrument/twin_floor.hpp"

#include <algorithm>
#include <cmath>
#include <span>

#include "piezoshift/plant/random.hpp"
#include "piezoshift/psi/fizeau_simulation.hpp"

namespace piezoshift::instrument {

double ideal_stage_error_rms_nm(const camera::TwinScene& scene, const camera::CameraConfig& cc,
                                const SequenceParams& params, const psi::AnalysisOptions& options) {
  const psi::CameraParams sensor = camera::sensor_params(cc);
  const double gain = std::pow(10.0, cc.settings.gain_dB / 20.0);
  const double top = std::ldexp(1.0, sensor.bit_depth) - 1.0;
  std::vector<psi::Map> frames;
  for (std::size_t k = 0; k < params.steps_rad.size(); ++k) {
    const psi::PoseSample still{0.0, step_piston_nm(params, k), 0.0, 0.0};
    plant::Rng rng(camera::frame_seed(scene.seed, k));
    psi::Map f = psi::render_frame(scene.surface_nm, scene.mask, scene.fizeau, sensor,
                                   std::span<const psi::PoseSample>(&still, 1), rng);
    for (double& v : f.v)
      v = std::min(top, std::round(v * gain));  // the twin camera's digital gain
    frames.push_back(std::move(f));
  }
  const psi::Analysis a = psi::analyze_frames(frames, scene.mask, options);
  return psi::surface_error_rms_nm(a.surface_nm, scene.surface_nm, a.valid);
}

}  // namespace piezoshift::instrument
