#include "piezoshift/reproduction/phase_measurement.hpp"

#include <stdexcept>

#include "piezoshift/instrument/acquisition.hpp"
#include "piezoshift/instrument/twin_floor.hpp"
#include "piezoshift/psi/analysis.hpp"
#include "piezoshift/psi/fizeau_simulation.hpp"
#include "piezoshift/runtime/loop_clock.hpp"
#include "piezoshift/runtime/sim_backend.hpp"

namespace piezoshift::reproduction {
namespace {

constexpr double kWavelength_nm = 632.8;  // HeNe, as `measure` takes it
constexpr psi::Algorithm kAlgorithm = psi::Algorithm::kHariharan5;

// `measure`'s sequence for Hariharan's algorithm and its defaults: k pi/2, one average.
instrument::SequenceParams sequence_params() {
  instrument::SequenceParams p;
  p.steps_rad = instrument::commanded_steps(kAlgorithm, {}, "steps");
  p.wavelength_nm = kWavelength_nm;
  return p;
}

// `measure`'s twin scene for the default surface.
camera::TwinScene twin_scene(const camera::CameraConfig& cc, std::uint64_t seed) {
  return camera::make_twin_scene(
      psi::SurfaceSpec{},
      camera::measurement_optics(cc.settings, cc.pupil_radius_m, kWavelength_nm), seed);
}

}  // namespace

PhaseMeasurement run_phase_measurement(const config::ProjectConfig& config,
                                       const control::SemiClosedLoopParams& controller,
                                       std::uint64_t seed, const runtime::SafetyLimits& limits) {
  PhaseMeasurement m;
  m.algorithm = std::string(psi::algorithm_name(kAlgorithm));
  m.params = sequence_params();
  m.scene = twin_scene(m.camera, seed);

  runtime::SimOptions so;
  so.design = config.design;
  so.twin = config.twin;
  so.seed = seed;
  so.rate_Hz = 1.0 / config.twin.daq.sample_time_s;
  runtime::SimBackend sim(so);
  sim.configure();
  runtime::SimulatedClock clock;
  instrument::LoopSetup loop;
  loop.controller = controller;
  loop.limits = limits;
  loop.rate_Hz = so.rate_Hz;  // the controller runs at the DAQ's rate, as on the bench

  camera::TwinCamera cam(m.scene, camera::sensor_params(m.camera));
  cam.configure(m.camera.settings);
  cam.start();
  m.sequence = instrument::acquire_sequence(sim, clock, &sim.twin(), cam, loop, m.params);
  cam.stop();
  m.simulated_time_s = static_cast<double>(m.sequence.ticks) * config.twin.daq.sample_time_s;
  if (!m.sequence.validity.valid) {
    m.validity.fail(m.sequence.validity.reason);
    return m;
  }

  psi::AnalysisOptions ao;
  ao.phase.algorithm = kAlgorithm;
  ao.phase.steps_rad = m.params.steps_rad;
  ao.wavelength_nm = kWavelength_nm;
  try {
    m.analysis = instrument::analyze_measurement(m.sequence, m.params, m.scene.mask, ao);
  } catch (const std::invalid_argument& e) {
    m.validity.fail(std::string("the frames carry no phase: ") + e.what());
    return m;
  }
  m.error_rms_nm =
      psi::surface_error_rms_nm(m.analysis.surface_nm, m.scene.surface_nm, m.analysis.valid);
  m.ideal_error_rms_nm = instrument::ideal_stage_error_rms_nm(m.scene, m.camera, m.params, ao);
  if (!m.analysis.converged)
    m.validity.fail(m.analysis.reason);
  return m;
}

}  // namespace piezoshift::reproduction
