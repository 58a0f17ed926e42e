#include "piezoshift/procedures/measure_run.hpp"

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "piezoshift/calibration/loop_calibration.hpp"
#include "piezoshift/camera/instrument_config.hpp"
#include "piezoshift/camera/make_camera.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/instrument/acquisition.hpp"
#include "piezoshift/instrument/fringe_actuator_scan.hpp"
#include "piezoshift/instrument/measurement_lock.hpp"
#include "piezoshift/instrument/sequence_memory.hpp"
#include "piezoshift/instrument/twin_floor.hpp"
#include "piezoshift/instrument/twin_measurement.hpp"
#include "piezoshift/procedures/loop_setup.hpp"
#include "piezoshift/procedures/loop_stack.hpp"
#include "piezoshift/procedures/work_begins.hpp"
#include "piezoshift/psi/phase_algorithms.hpp"
#include "piezoshift/psi/png_image.hpp"
#include "piezoshift/psi/pupil_detection.hpp"
#include "piezoshift/runtime/safety_ranges.hpp"

namespace piezoshift::procedures {

namespace {

// Everything a measurement needs before the loop starts.
struct Setup {
  camera::InstrumentConfig config;
  psi::Algorithm algorithm = psi::Algorithm::kHariharan5;
  instrument::SequenceParams params;
  std::optional<camera::TwinScene> scene;
  calibration::LoopCalibration calibration;
};

instrument::SequenceParams sequence_params(const MeasureRequest& r, psi::Algorithm alg) {
  instrument::SequenceParams p;
  p.steps_rad =
      instrument::commanded_steps(alg, r.steps_rad, option_name(r, "--steps-rad", "steps_rad"));
  p.base_um = r.base_um;
  p.on_target = r.on_target;
  p.averages = r.averages;
  p.frame_timeout_s = r.frame_timeout_s;
  p.hold_s = r.hold_s;
  p.trigger =
      r.trigger == "line" ? instrument::TriggerMode::kLine : instrument::TriggerMode::kSoftware;
  if (const std::string why = instrument::sequence_problem(p); !why.empty())
    throw core::InputError("measure: " + why);
  return p;
}

LoopStackOptions stack_options(const MeasureRequest& r) {
  LoopStackOptions so;
  so.daq = r.daq;
  so.rate_Hz = r.rate_Hz;
  so.seed = r.seed;
  so.config_path = r.config_file;
  so.clock = r.free_run ? StackClock::kFreeRun : StackClock::kRealTime;
  so.trigger_line = r.trigger_line;
  return so;
}

// A file or a controller, checked at the loop's rate; none: resolve_calibration's (Python's
// start-up calibration says nothing on stderr).
calibration::LoopCalibration resolve(const MeasureRequest& r, const config::ProjectConfig& c) {
  const double ts = 1.0 / r.rate_Hz;
  if (r.controller) {
    calibration::LoopCalibration lc;
    lc.params = *r.controller;
    lc.source = "a controller from Python";
    calibration::check_at_loop_rate(lc.params, ts, lc.source);
    return lc;
  }
  if (r.caller == MeasureCaller::kPython && r.calibration_file.empty())
    return calibration::startup_calibration(c, r.seed, r.max_physics_steps,
                                            "a calibration file or controller");
  return resolve_calibration(r.calibration_file, r.daq, c, r.seed, ts, r.max_physics_steps);
}

// The pupil given: Python's array or the CLI's PNG, of width x height (`of`: what it must match).
psi::Mask given_mask(const MeasureRequest& r, int width_px, int height_px, std::string_view of) {
  if (r.mask) {
    if (r.mask->width != width_px || r.mask->height != height_px)
      throw core::InputError(
          fmt::format("mask: expected a ({}, {}) array, the frames' size", height_px, width_px));
    return *r.mask;
  }
  return psi::read_mask_of_size(r.mask_file, width_px, height_px, of);
}

bool mask_given(const MeasureRequest& r) {
  return r.mask.has_value() || !r.mask_file.empty();
}

// The fringe lock, asked for by `who` (instrument::lock_requested_by). Its pupil: the twin
// camera's scene's; the mask given; else found from the lock's reference frames (Aravis's fake
// camera fed the twin too: a real camera knows no scene).
instrument::LockSetup lock_setup(const MeasureRequest& r, const Setup& s, const std::string& who) {
  psi::Mask mask;
  const camera::CameraSettings& cs = s.config.camera.settings;
  if (s.scene && r.camera == "twin")
    mask = s.scene->mask;
  else if (mask_given(r))
    mask = given_mask(r, cs.width_px, cs.height_px, "the camera's frames");
  return instrument::measurement_lock_setup(std::move(mask), s.config.camera.pupil_radius_m,
                                            s.config.installation.project.twin.geometry,
                                            s.calibration, r.lock_retake_s, s.params, who);
}

// Everything before the loop starts, checked in this order so that bad input is named before
// anything runs: the request, configuration, the sequence and its memory, the twin's scene.
Setup prepare(const MeasureRequest& r) {
  validate(r);
  Setup s;
  if (!r.config_file.empty())
    s.config = camera::load_instrument_config(r.config_file);
  s.algorithm = psi::parse_algorithm(r.algorithm);
  s.params = sequence_params(r, s.algorithm);
  if (r.trigger == "line")
    s.config.camera.settings.trigger = camera::TriggerSource::kLine;
  // Before anything runs: the frames of every average are held to the end.
  if (const std::string why =
          instrument::sequence_memory_problem(s.params, s.config.camera.settings);
      !why.empty())
    throw core::InputError(fmt::format(
        "measure: {} and {} ({}) with [camera] width_px, "
        "height_px: {}",
        option_name(r, "--averages", "averages"), option_name(r, "--algorithm", "algorithm"),
        option_name(r, "--steps-rad", "steps_rad"), why));
  work_begins();  // the twin's scene, the stage, the camera
  if (r.camera == "twin" || fed_by_twin(r)) {
    const psi::SurfaceSpec spec =
        r.surface.empty() ? psi::SurfaceSpec{} : psi::parse_surface_spec(r.surface);
    s.scene = instrument::measurement_scene(spec, s.config.camera, s.params, r.seed);
  }
  return s;
}

// The stack's calibration, the lock and the travel: after the stack, as the DAQ is named first.
void resolve_controller(const MeasureRequest& r, Setup& s) {
  s.calibration = resolve(r, s.config.installation.project);
  if (const std::optional<std::string> who =
          instrument::lock_requested_by(r.lock, option_name(r, "--lock", "lock"), s.calibration))
    s.params.lock = lock_setup(r, s, *who);
  if (const std::string why =
          instrument::travel_problem(s.params, s.calibration.travel_z_max_um, s.calibration.source);
      !why.empty())
    throw core::InputError(option_name(r, "--base-um: ", "measure: ") + why);
}

// The loop, the camera and the sequence; the DAQ's outputs at 0 V whatever happens.
void acquire(const MeasureRequest& r, Setup& s, LoopStack& stack, const MeasureHooks& hooks,
             MeasureOutcome& out) {
  instrument::LoopSetup loop;
  loop.controller = s.calibration.params;
  loop.limits = runtime::resolve_overrun_trip(
      loop_safety_limits(s.config.installation.safety, std::nullopt), stack.sim() != nullptr);
  loop.rate_Hz = r.rate_Hz;
  if (hooks.stop_on_signals)
    loop.stop_signal = &g_stop_signal;
  std::unique_ptr<camera::Camera> cam =
      camera::make_camera(r.camera, s.config.camera, s.scene ? &*s.scene : nullptr);
  cam->start();
  std::optional<StopSignals> signals;
  if (hooks.stop_on_signals)
    signals.emplace();
  if (stack.clock().real_time())
    request_realtime_or_warn(r.cpu);
  const plant::Twin* twin = stack.sim() != nullptr ? &stack.sim()->twin() : nullptr;
  out.sequence = instrument::acquire_sequence(stack.daq(), stack.clock(), twin, *cam, loop,
                                              s.params, hooks.progress);
  cam->stop();
  out.camera = cam->name();
  out.daq = stack.name();
  out.real_time = stack.clock().real_time();
}

// The pupil analysed: the twin's scene's unless one was given, else found from the first
// average's fringe modulation (nothing: the measurement failed, kNoPupil).
std::optional<psi::Mask> analysis_mask(const MeasureRequest& r, const Setup& s,
                                       MeasureOutcome& out) {
  const std::size_t n = s.params.steps_rad.size();
  if (s.scene && !mask_given(r))
    return s.scene->mask;
  const std::vector<psi::Map> frames = instrument::frame_maps(std::vector<camera::Frame>(
      out.sequence.frames.begin(), out.sequence.frames.begin() + static_cast<long>(n)));
  if (mask_given(r))  // the user's: bad input if it is not the frames' size
    return given_mask(r, frames.front().width, frames.front().height, "the frames");
  try {
    return psi::pupil_from_modulation(frames).mask;
  } catch (const std::invalid_argument& e) {
    out.end = MeasureEnd::kNoPupil;
    out.reason = fmt::format("measure: {}", e.what());
    return std::nullopt;
  }
}

void analyse(const MeasureRequest& r, const Setup& s, MeasureOutcome& out) {
  std::optional<psi::Mask> mask = analysis_mask(r, s, out);
  if (!mask)
    return;
  out.mask = std::move(*mask);
  const psi::AnalysisOptions ao = instrument::measurement_analysis_options(s.algorithm, s.params);
  try {
    out.analysis = instrument::analyze_measurement(out.sequence, s.params, out.mask, ao);
  } catch (const std::invalid_argument& e) {
    out.end = MeasureEnd::kNoPhase;
    out.reason = fmt::format("measure: the frames carry no phase: {}", e.what());
    return;
  }
  out.m_per_px = instrument::plate_m_per_px(out.mask, s.config.camera.pupil_radius_m);
  if (s.scene) {
    out.truth_nm = s.scene->surface_nm;
    const instrument::TwinErrors e =
        instrument::twin_errors(*s.scene, s.config.camera, s.params, *out.analysis, ao);
    out.error_rms_nm = e.error_rms_nm;
    out.ideal_error_rms_nm = e.ideal_error_rms_nm;
  }
  // The twin camera's frame ids are its noise draws' (the fed Aravis camera's are Aravis's).
  if (s.scene && r.camera == "twin")
    out.floor_error_rms_nm = instrument::ideal_measurement_error_rms_nm(*s.scene, s.config.camera,
                                                                        s.params, out.sequence, ao);
  if (!out.analysis->converged) {
    out.end = MeasureEnd::kNotConverged;
    out.reason = "measure: " + out.analysis->reason;
  }
}

}  // namespace

MeasureOutcome run_measure(const MeasureRequest& r, const MeasureHooks& hooks) {
  Setup s = prepare(r);
  LoopStack stack(stack_options(r), s.config.installation.project);
  if (s.params.trigger == instrument::TriggerMode::kLine && !stack.daq().has_trigger_line())
    throw core::InputError(fmt::format("{} line: DAQ {} has no trigger line",
                                       option_name(r, "--trigger", "trigger"), stack.name()));
  resolve_controller(r, s);

  MeasureOutcome out;
  out.algorithm = std::string(psi::algorithm_name(s.algorithm));
  out.calibration_source = s.calibration.source;
  out.rate_Hz = r.rate_Hz;
  acquire(r, s, stack, hooks, out);
  out.params = s.params;
  if (!out.sequence.validity.valid) {
    out.end = out.sequence.validity.reason.find("safety supervisor") != std::string::npos
                  ? MeasureEnd::kFault
                  : MeasureEnd::kNotValid;
    out.reason = "measure: " + out.sequence.validity.reason;
    return out;
  }
  analyse(r, s, out);
  return out;
}

}  // namespace piezoshift::procedures
