#include "piezoshift/instrument/twin_measurement.hpp"

#include "piezoshift/instrument/twin_floor.hpp"
#include "piezoshift/runtime/loop_clock.hpp"
#include "piezoshift/runtime/sim_backend.hpp"

namespace piezoshift::instrument {

camera::TwinScene measurement_scene(const psi::SurfaceSpec& surface, const camera::CameraConfig& cc,
                                    const SequenceParams& params, std::uint64_t seed) {
  return camera::make_twin_scene(
      surface, camera::measurement_optics(cc.settings, cc.pupil_radius_m, params.wavelength_nm),
      seed);
}

psi::AnalysisOptions measurement_analysis_options(psi::Algorithm algorithm,
                                                  const SequenceParams& params) {
  psi::AnalysisOptions ao;
  ao.phase.algorithm = algorithm;
  ao.phase.steps_rad = params.steps_rad;
  ao.wavelength_nm = params.wavelength_nm;
  return ao;
}

SequenceResult acquire_on_simulated_twin(const config::ProjectConfig& project, std::uint64_t seed,
                                         double rate_Hz, const std::string& source,
                                         camera::Camera& camera, const LoopSetup& loop,
                                         const SequenceParams& params) {
  runtime::SimOptions so;
  so.design = project.design;
  so.twin = project.twin;
  so.seed = seed;
  so.rate_Hz = rate_Hz;
  if (!source.empty())
    so.source = source;
  runtime::SimBackend sim(so);
  sim.configure();
  runtime::SimulatedClock clock;
  return acquire_sequence(sim, clock, &sim.twin(), camera, loop, params);
}

TwinErrors twin_errors(const camera::TwinScene& scene, const camera::CameraConfig& cc,
                       const SequenceParams& params, const MeasurementAnalysis& analysis,
                       const psi::AnalysisOptions& options) {
  TwinErrors e;
  e.error_rms_nm = psi::surface_error_rms_nm(analysis.surface_nm, scene.surface_nm, analysis.valid);
  e.ideal_error_rms_nm = ideal_stage_error_rms_nm(scene, cc, params, options);
  return e;
}

}  // namespace piezoshift::instrument
