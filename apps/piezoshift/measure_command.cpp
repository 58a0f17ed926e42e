// `piezoshift measure`: one phase-shifting measurement through the shipping loop (docs/measure.md):
// the stage steps through the algorithm's sequence on the loop `run` and `serve` run, the camera
// exposes once the stage has settled, then the analysis of `psi analyze`.
//
// Exit status: 0 a measurement was written; 2 bad input (options, files, a camera that cannot be
// opened or cannot take the settings); 3 the safety supervisor latched a fault; 4 not valid: a
// step that did not settle, a frame lost or late, a fit that did not converge (nothing written).
#include <unistd.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "measure_report.hpp"
#include "physics_budget.hpp"
#include "piezoshift/camera/camera.hpp"
#include "piezoshift/camera/camera_config.hpp"
#include "piezoshift/camera/instrument_config.hpp"
#include "piezoshift/camera/make_camera.hpp"
#include "piezoshift/camera/twin_camera.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/instrument/acquisition.hpp"
#include "piezoshift/instrument/fringe_actuator_scan.hpp"
#include "piezoshift/instrument/hold_summary.hpp"
#include "piezoshift/instrument/measurement.hpp"
#include "piezoshift/instrument/measurement_lock.hpp"
#include "piezoshift/instrument/sequence.hpp"
#include "piezoshift/instrument/sequence_memory.hpp"
#include "piezoshift/instrument/twin_floor.hpp"
#include "piezoshift/procedures/loop_setup.hpp"
#include "piezoshift/procedures/loop_stack.hpp"
#include "piezoshift/psi/analysis.hpp"
#include "piezoshift/psi/fizeau_simulation.hpp"
#include "piezoshift/rig/validity.hpp"
#include "piezoshift/runtime/control_loop.hpp"
#include "piezoshift/runtime/safety_ranges.hpp"
#include "progress_bar.hpp"
#include "psi_options.hpp"
#include "whole_number.hpp"

namespace piezoshift::app {

namespace {

struct MeasureOptions {
  double max_physics_steps = plant::kDefaultPhysicsStepBudget;  // the start-up calibration
  std::string camera = "twin";
  std::string daq = "sim";
  double rate_Hz = 1000.0;
  std::string calibration;
  std::string config;
  std::string algorithm = "hariharan5";
  std::string steps_rad;
  int averages = 1;
  std::string surface;
  std::string mask;
  double base_um = 5.0;
  psi::OnTarget on_target{};
  double frame_timeout_s = 2.0;
  std::uint64_t seed = 1;
  bool free_run = false;
  std::string trigger = "software";
  std::string trigger_line;
  int cpu = -1;
  std::string out;
  bool json = false;
  bool lock = false;
  double lock_retake_s = instrument::LockSetup{}.retake_s;
  double hold_s = 0.0;
};

instrument::SequenceParams sequence_params(const MeasureOptions& o, psi::Algorithm alg,
                                           double wavelength_nm) {
  instrument::SequenceParams p;
  p.steps_rad = instrument::commanded_steps(
      alg, o.steps_rad.empty() ? std::vector<double>{} : parse_list(o.steps_rad, "--steps-rad"),
      "--steps-rad");
  p.wavelength_nm = wavelength_nm;
  p.base_um = o.base_um;
  p.on_target = o.on_target;
  p.averages = o.averages;
  p.frame_timeout_s = o.frame_timeout_s;
  p.hold_s = o.hold_s;
  p.trigger =
      o.trigger == "line" ? instrument::TriggerMode::kLine : instrument::TriggerMode::kSoftware;
  if (const std::string why = instrument::sequence_problem(p); !why.empty())
    throw core::InputError("measure: " + why);
  return p;
}

procedures::LoopStackOptions stack_options(const MeasureOptions& o) {
  procedures::LoopStackOptions so;
  so.daq = o.daq;
  so.rate_Hz = o.rate_Hz;
  so.seed = o.seed;
  so.config_path = o.config;
  so.clock = o.free_run ? procedures::StackClock::kFreeRun : procedures::StackClock::kRealTime;
  so.trigger_line = o.trigger_line;
  return so;
}

// The twin camera's scene: the --surface on a pupil of 0.47 of the frame's side, drawn as
// `psi simulate` draws it for the same spec and seed, rendered with the Fizeau's optics.
camera::TwinScene twin_scene(const MeasureOptions& o, const camera::CameraConfig& cc,
                             double wavelength_nm) {
  const psi::SurfaceSpec spec =
      o.surface.empty() ? psi::SurfaceSpec{} : psi::parse_surface_spec(o.surface);
  return camera::make_twin_scene(
      spec, camera::measurement_optics(cc.settings, cc.pupil_radius_m, wavelength_nm), o.seed);
}

// Everything a measurement needs before the loop starts, checked in this order so that bad input
// is named before anything runs: options, configuration, the stack (DAQ), the calibration, the
// camera.
struct MeasureSetup {
  camera::InstrumentConfig config;
  psi::Algorithm algorithm = psi::Algorithm::kHariharan5;
  instrument::SequenceParams params;
  std::optional<camera::TwinScene> scene;
  procedures::LoopCalibration calibration;
};

// Aravis's in-process fake camera on the twin: shown the twin's fringes (twin_fed_camera.hpp).
bool fed_by_twin(const MeasureOptions& o) {
  return o.camera.starts_with("aravis:Fake") && o.daq == "sim";
}

// --trigger line needs a DAQ with a trigger output (the twin's, or a Comedi board's
// --trigger-line) and a camera whose line it can reach.
void check_trigger(const MeasureOptions& o) {
  if (o.trigger != "software" && o.trigger != "line")
    throw core::InputError(fmt::format("--trigger '{}': expected software or line", o.trigger));
  if (o.trigger == "software" && !o.trigger_line.empty())
    throw core::InputError("--trigger-line: the DAQ's trigger output is used by --trigger line");
  if (o.trigger != "line")
    return;
  if (o.daq != "sim" && o.trigger_line.empty())
    throw core::InputError(fmt::format(
        "--trigger line: DAQ {} has no trigger line (give --trigger-line SUBDEVICE/CHANNEL, a "
        "digital output of the board: 2/0 is the PCI-6229's P0.0)",
        o.daq));
  if (o.camera.starts_with("aravis:Fake"))
    throw core::InputError(
        fmt::format("--trigger line: camera {} has no line input (Aravis's fake camera "
                    "free-runs at 25 Hz on a line trigger); use --trigger software",
                    o.camera));
}

void check_options(const MeasureOptions& o) {
  procedures::check_loop_rate(o.rate_Hz);
  check_trigger(o);
  if (o.out.empty())
    throw core::InputError("--out: a folder for the measurement is required");
  check_measure_out(o.out);
  if (o.camera == "twin" && o.daq != "sim")
    throw core::InputError(
        fmt::format("--camera twin renders the twin's plate: it needs --daq sim, not {}", o.daq));
  if (o.camera != "twin" && !fed_by_twin(o) && !o.surface.empty())
    throw core::InputError(
        "--surface: the test surface of the twin camera (or of aravis:Fake_1 on --daq sim)");
  // It used to be ignored: the twin analyses the pupil it renders.
  if (o.camera == "twin" && !o.mask.empty())
    throw core::InputError(
        "--mask: the twin camera renders its own pupil and analyses it; --mask is the pupil of "
        "other cameras");
}

// The fringe lock, asked for by `who` (instrument::lock_requested_by). Its pupil: the twin
// camera's scene's; --mask; else found from the lock's reference frames (Aravis's fake camera
// fed the twin too: a real camera knows no scene).
instrument::LockSetup lock_setup(const MeasureOptions& o, const MeasureSetup& s,
                                 const std::string& who) {
  psi::Mask mask;
  if (s.scene && o.camera == "twin") {
    mask = s.scene->mask;
  } else if (!o.mask.empty()) {
    const camera::CameraSettings& cs = s.config.camera.settings;
    mask = read_mask_of_size(o.mask, cs.width_px, cs.height_px, "the camera's frames");
  }
  return instrument::measurement_lock_setup(std::move(mask), s.config.camera.pupil_radius_m,
                                            s.config.installation.project.twin.geometry,
                                            s.calibration, o.lock_retake_s, s.params, who);
}

void check_travel(const MeasureSetup& s) {
  if (const std::string why =
          instrument::travel_problem(s.params, s.calibration.travel_z_max_um, s.calibration.source);
      !why.empty())
    throw core::InputError("--base-um: " + why);
}

std::unique_ptr<camera::Camera> open_camera(const MeasureOptions& o, const MeasureSetup& s) {
  std::unique_ptr<camera::Camera> cam =
      camera::make_camera(o.camera, s.config.camera, s.scene ? &*s.scene : nullptr);
  cam->start();
  return cam;
}

psi::Mask measurement_mask(const MeasureOptions& o, const MeasureSetup& s,
                           const instrument::SequenceResult& r) {
  // --mask first (never with the twin camera, check_options): Aravis's fake camera fed the
  // twin takes it too, as its lock does.
  const std::size_t n = s.params.steps_rad.size();
  if (s.scene && o.mask.empty())
    return s.scene->mask;
  const std::vector<psi::Map> frames = instrument::frame_maps(
      std::vector<camera::Frame>(r.frames.begin(), r.frames.begin() + static_cast<long>(n)));
  if (!o.mask.empty())
    return choose_pupil(o.mask, frames, "measure").mask;  // the user's file: bad input if wrong
  try {
    return choose_pupil("", frames, "measure").mask;
  } catch (const core::InputError& e) {  // frames without a pupil: a measurement that failed
    throw rig::ProcedureFailed(e.what());
  }
}

struct Outcome {
  instrument::SequenceResult sequence;
  std::string camera_name;
  std::string daq_name;
  bool real_time = true;
};

// The loop, the camera and the sequence; the DAQ's outputs at 0 V whatever happens.
Outcome acquire(const MeasureOptions& o, MeasureSetup& s, procedures::LoopStack& stack) {
  instrument::LoopSetup loop;
  loop.controller = s.calibration.params;
  loop.limits = runtime::resolve_overrun_trip(
      procedures::loop_safety_limits(s.config.installation.safety, std::nullopt),
      stack.sim() != nullptr);
  loop.rate_Hz = o.rate_Hz;
  loop.stop_signal = &procedures::g_stop_signal;
  std::unique_ptr<camera::Camera> cam = open_camera(o, s);
  procedures::StopSignals signals;
  ProgressBar bar(1);
  if (stack.clock().real_time())
    procedures::request_realtime_or_warn(o.cpu);
  const plant::Twin* twin = stack.sim() != nullptr ? &stack.sim()->twin() : nullptr;
  Outcome out;
  out.sequence = instrument::acquire_sequence(stack.daq(), stack.clock(), twin, *cam, loop,
                                              s.params, bar.callback());
  cam->stop();
  out.camera_name = cam->name();
  out.daq_name = stack.name();
  out.real_time = stack.clock().real_time();
  return out;
}

int measure(const MeasureOptions& o) {
  check_options(o);
  MeasureSetup s;
  if (!o.config.empty())
    s.config = camera::load_instrument_config(o.config);
  const double wavelength_nm = 632.8;
  s.algorithm = psi::parse_algorithm(o.algorithm);
  s.params = sequence_params(o, s.algorithm, wavelength_nm);
  if (o.trigger == "line")
    s.config.camera.settings.trigger = camera::TriggerSource::kLine;
  // Before anything runs: the frames of every average are held to the end.
  if (const std::string why =
          instrument::sequence_memory_problem(s.params, s.config.camera.settings);
      !why.empty())
    throw core::InputError(
        "measure: --averages and --algorithm (--steps-rad) with [camera] width_px, height_px: " +
        why);
  work_begins();  // the twin's scene, the stage, the camera
  if (o.camera == "twin" || fed_by_twin(o))
    s.scene = twin_scene(o, s.config.camera, wavelength_nm);
  procedures::LoopStack stack(stack_options(o), s.config.installation.project);
  if (s.params.trigger == instrument::TriggerMode::kLine && !stack.daq().has_trigger_line())
    throw core::InputError(fmt::format("--trigger line: DAQ {} has no trigger line", stack.name()));
  s.calibration =
      procedures::resolve_calibration(o.calibration, o.daq, s.config.installation.project, o.seed,
                                      1.0 / o.rate_Hz, o.max_physics_steps);
  if (const std::optional<std::string> who =
          instrument::lock_requested_by(o.lock, "--lock", s.calibration))
    s.params.lock = lock_setup(o, s, *who);
  check_travel(s);

  const Outcome acquired = acquire(o, s, stack);
  const instrument::SequenceResult& r = acquired.sequence;
  if (!r.validity.valid) {
    if (o.json)
      fmt::print("{}\n", nlohmann::json{{"valid", false}, {"reason", r.validity.reason}}.dump(2));
    if (r.validity.reason.find("safety supervisor") != std::string::npos) {
      fmt::print(stderr, "piezoshift: measure: {}\n", r.validity.reason);
      return kExitFault;
    }
    throw rig::ProcedureFailed("measure: " + r.validity.reason);
  }
  const psi::Mask mask = measurement_mask(o, s, r);
  psi::AnalysisOptions ao;
  ao.phase.algorithm = s.algorithm;
  ao.phase.steps_rad = s.params.steps_rad;
  ao.wavelength_nm = wavelength_nm;
  instrument::MeasurementAnalysis a;
  try {
    a = instrument::analyze_measurement(r, s.params, mask, ao);
  } catch (const std::invalid_argument& e) {
    throw rig::ProcedureFailed(fmt::format("measure: the frames carry no phase: {}", e.what()));
  }
  MeasureRecord rec{.camera = acquired.camera_name,
                    .daq = acquired.daq_name,
                    .algorithm = std::string(psi::algorithm_name(s.algorithm)),
                    .calibration_source = s.calibration.source,
                    .rate_Hz = o.rate_Hz,
                    .real_time = acquired.real_time,
                    .params = &s.params,
                    .sequence = &r,
                    .analysis = &a,
                    .mask = &mask,
                    .truth_nm = s.scene ? &s.scene->surface_nm : nullptr,
                    .error_rms_nm = std::nullopt,
                    .ideal_error_rms_nm = std::nullopt,
                    .floor_error_rms_nm = std::nullopt,
                    .out = {},
                    .out_given = {},
                    .m_per_px = instrument::plate_m_per_px(mask, s.config.camera.pupil_radius_m)};
  if (s.scene) {
    rec.error_rms_nm = psi::surface_error_rms_nm(a.surface_nm, s.scene->surface_nm, a.valid);
    rec.ideal_error_rms_nm =
        instrument::ideal_stage_error_rms_nm(*s.scene, s.config.camera, s.params, ao);
  }
  // The twin camera's frame ids are its noise draws' (the fed Aravis camera's are Aravis's).
  if (s.scene && o.camera == "twin")
    rec.floor_error_rms_nm =
        instrument::ideal_measurement_error_rms_nm(*s.scene, s.config.camera, s.params, r, ao);
  if (!a.converged) {
    if (o.json)
      fmt::print("{}\n", measure_json(rec).dump(2));
    throw rig::ProcedureFailed("measure: " + a.reason);
  }
  write_measurement(rec, o.out);
  if (o.json) {
    fmt::print("{}\n", measure_json(rec).dump(2));
  } else {
    fmt::print(
        "measure: {} frames x {} on {} with camera {}: surface RMS {:.3f} nm, PV {:.3f} nm"
        "{}\nsteps: worst recovered - true {}; wall time {:.3f} s (floor {:.3f} s); "
        "overruns {}\nwritten: {}/\n",
        s.params.steps_rad.size(), s.params.averages, rec.daq, rec.camera, a.figures.rms,
        a.figures.pv,
        rec.error_rms_nm ? fmt::format(", measured - true {:.3f} nm RMS", *rec.error_rms_nm)
                         : std::string(),
        a.step_error_text(), r.wall_time_s, r.floor_s, r.overruns, rec.out);
    if (!r.hold.empty()) {
      const std::optional<double> rms = instrument::hold_summary(r).path_error_rms_nm;
      fmt::print("hold: {} frames over {:.1f} s{}\n", r.hold.size(), o.hold_s,
                 rms ? fmt::format(", the cavity's path from its set point {:.3f} nm RMS", *rms)
                     : std::string());
    }
    if (r.lock)
      fmt::print(
          "lock: {} frames locked, {} without a pose ({} lost, {} taken again){}\n", r.lock->locked,
          r.lock->holding, r.lock->lost, r.lock->retaken,
          r.lock->first_refusal.empty() ? std::string() : "; first: " + r.lock->first_refusal);
  }
  return 0;
}

}  // namespace

void add_measure_command(CLI::App& app, Action& action) {
  auto o = std::make_shared<MeasureOptions>();
  CLI::App* cmd = app.add_subcommand(
      "measure",
      "Take a phase-shifting measurement: the stage steps through the shipping loop, the camera "
      "exposes once it has settled, then the analysis (docs/measure.md)");
  cmd->add_option("--camera", o->camera, "twin, files:DIR or aravis:ID (docs/camera.md)")
      ->capture_default_str();
  cmd->add_option("--daq", o->daq, "sim, or comedi:/dev/comediN")->capture_default_str();
  cmd->add_option("--rate-hz", o->rate_Hz, "loop rate, 1000 (the paper) to 10000 Hz")
      ->capture_default_str();
  cmd->add_option("--calibration", o->calibration,
                  "TOML with [controller] (the paper's or the improved controller)");
  cmd->add_option("--config", o->config,
                  "TOML configuration: the twin's sections, [safety] and [camera]");
  cmd->add_option("--algorithm", o->algorithm,
                  "4step, carre, hariharan5, degroot7, frame13, lsq, aia, tilt-aia")
      ->capture_default_str();
  cmd->add_option("--steps-rad", o->steps_rad,
                  "commanded steps, comma-separated, the first 0 (lsq, aia, tilt-aia)");
  cmd->add_option("--averages", o->averages, "measurements averaged, 1 to 100")
      ->capture_default_str()
      ->check(whole_number(1, 100));
  cmd->add_option("--surface", o->surface,
                  "the twin camera's test surface, as `psi simulate` takes it (Z4=40,rough=0.5)");
  cmd->add_option("--mask", o->mask,
                  "the pupil as a PNG (cameras other than the twin; the lock's too)");
  cmd->add_option("--base-um", o->base_um, "Z_d of P1..P3 at frame 0 (um)")->capture_default_str();
  cmd->add_option("--settle-band-nm", o->on_target.band_nm,
                  "settled: mean S - feedback within this on every channel (nm)")
      ->capture_default_str();
  cmd->add_option("--settle-hold-s", o->on_target.hold_s, "... averaged over this long (s)")
      ->capture_default_str();
  cmd->add_option("--settle-timeout-s", o->on_target.timeout_s,
                  "a step not settled by then ends the measurement (s)")
      ->capture_default_str();
  cmd->add_option("--frame-timeout-s", o->frame_timeout_s,
                  "a frame not arrived by then ends the measurement (s)")
      ->capture_default_str();
  add_physics_budget_option(cmd, o->max_physics_steps);
  cmd->add_option("--seed", o->seed, "twin and camera noise seed")
      ->capture_default_str()
      ->check(whole_number(0, kAnyUnsigned));
  cmd->add_option("--trigger", o->trigger,
                  "software (camera.trigger() between ticks) or line (a pulse on the DAQ's "
                  "trigger line written by the loop's tick; the camera's trigger source a line)")
      ->capture_default_str();
  cmd->add_option("--trigger-line", o->trigger_line,
                  "comedi: the trigger output as SUBDEVICE/CHANNEL (2/0: the PCI-6229's P0.0)");
  cmd->add_flag("--free-run", o->free_run,
                "sim only: simulated clock, as fast as possible (tests, benches)");
  cmd->add_option("--cpu", o->cpu, "CPU to pin the loop to (-1: the last one, -2: none)")
      ->capture_default_str();
  cmd->add_flag("--lock", o->lock,
                "hold the Fizeau cavity on the fringes (docs/fizeau.md): the first average's "
                "first four frames are the reference; the pupil: the twin camera's, --mask, "
                "else found in them (a calibration file's [controller] outer = \"fringes\" "
                "asks for it too, with its [fringe_lock])");
  cmd->add_option("--lock-retake-s", o->lock_retake_s,
                  "with --lock: a frame whose fringes were lost is taken again until they come "
                  "back, for at most this long (s, in (0, 60]); then the measurement fails")
      ->capture_default_str();
  cmd->add_option("--hold-s", o->hold_s,
                  "after the measurement, hold the stage at frame 0 for this long while the "
                  "camera exposes frame after frame (with --lock, the lock holds the cavity; "
                  "hold.csv, hold.png), 0 to 3600 s")
      ->capture_default_str();
  cmd->add_option("--out", o->out, "a new folder for the measurement")->required();
  cmd->add_flag("--json", o->json, "print the summary as JSON");
  cmd->callback([&action, o] { action = [o] { return measure(*o); }; });
}

}  // namespace piezoshift::app
