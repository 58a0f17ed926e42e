#include "piezoshift/reproduction/phase_measurement.hpp"

#include <stdexcept>

#include "piezoshift/instrument/twin_measurement.hpp"

namespace piezoshift::reproduction {
namespace {

constexpr psi::Algorithm kAlgorithm = psi::Algorithm::kHariharan5;

// `measure`'s sequence for Hariharan's algorithm and its defaults: k pi/2, one average.
instrument::SequenceParams sequence_params() {
  instrument::SequenceParams p;
  p.steps_rad = instrument::commanded_steps(kAlgorithm, {}, "steps");
  return p;
}

}  // namespace

PhaseMeasurement run_phase_measurement(const config::ProjectConfig& config,
                                       const control::SemiClosedLoopParams& controller,
                                       std::uint64_t seed, const runtime::SafetyLimits& limits) {
  PhaseMeasurement m;
  m.algorithm = std::string(psi::algorithm_name(kAlgorithm));
  m.params = sequence_params();
  m.scene = instrument::measurement_scene(psi::SurfaceSpec{}, m.camera, m.params, seed);

  instrument::LoopSetup loop;
  loop.controller = controller;
  loop.limits = limits;
  loop.rate_Hz = 1.0 / config.twin.daq.sample_time_s;  // the DAQ's rate, as on the bench

  camera::TwinCamera cam(m.scene, camera::sensor_params(m.camera));
  cam.configure(m.camera.settings);
  cam.start();
  m.sequence =
      instrument::acquire_on_simulated_twin(config, seed, loop.rate_Hz, "", cam, loop, m.params);
  cam.stop();
  m.simulated_time_s = static_cast<double>(m.sequence.ticks) * config.twin.daq.sample_time_s;
  if (!m.sequence.validity.valid) {
    m.validity.fail(m.sequence.validity.reason);
    return m;
  }

  const psi::AnalysisOptions ao = instrument::measurement_analysis_options(kAlgorithm, m.params);
  try {
    m.analysis = instrument::analyze_measurement(m.sequence, m.params, m.scene.mask, ao);
  } catch (const std::invalid_argument& e) {
    m.validity.fail(std::string("the frames carry no phase: ") + e.what());
    return m;
  }
  const instrument::TwinErrors e =
      instrument::twin_errors(m.scene, m.camera, m.params, m.analysis, ao);
  m.error_rms_nm = e.error_rms_nm;
  m.ideal_error_rms_nm = e.ideal_error_rms_nm;
  if (!m.analysis.converged)
    m.validity.fail(m.analysis.reason);
  return m;
}

}  // namespace piezoshift::reproduction
