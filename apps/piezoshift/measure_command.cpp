// `piezoshift measure`: one phase-shifting measurement through the shipping loop (docs/measure.md):
// the stage steps through the algorithm's sequence on the loop `run` and `serve` run, the camera
// exposes once the stage has settled, then the analysis of `psi analyze`. The measurement itself
// is procedures::run_measure's (Python's measure() runs the same); this parses the options into
// its request, writes the outcome into --out and prints it.
//
// Exit status: 0 a measurement was written; 2 bad input (options, files, a camera that cannot be
// opened or cannot take the settings); 3 the safety supervisor latched a fault; 4 not valid: a
// step that did not settle, a frame lost or late, a fit that did not converge (nothing written).
#include <memory>
#include <optional>
#include <string>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "measure_report.hpp"
#include "physics_budget.hpp"
#include "piezoshift/instrument/hold_summary.hpp"
#include "piezoshift/instrument/sequence.hpp"
#include "piezoshift/procedures/measure_json.hpp"
#include "piezoshift/procedures/measure_run.hpp"
#include "piezoshift/rig/validity.hpp"
#include "progress_bar.hpp"
#include "psi_options.hpp"
#include "whole_number.hpp"

namespace piezoshift::app {

namespace {

// The options as given: the request, and what the CLI turns into it (the steps as text).
struct MeasureOptions {
  procedures::MeasureRequest request;
  std::string steps_rad;
  bool json = false;
};

void print_summary(const procedures::MeasureOutcome& m, const std::string& out) {
  const instrument::SequenceResult& r = m.sequence;
  const instrument::MeasurementAnalysis& a = *m.analysis;
  fmt::print(
      "measure: {} frames x {} on {} with camera {}: surface RMS {:.3f} nm, PV {:.3f} nm"
      "{}\nsteps: worst recovered - true {}; wall time {:.3f} s (floor {:.3f} s); "
      "overruns {}\nwritten: {}/\n",
      m.params.steps_rad.size(), m.params.averages, m.daq, m.camera, a.figures.rms, a.figures.pv,
      m.error_rms_nm ? fmt::format(", measured - true {:.3f} nm RMS", *m.error_rms_nm)
                     : std::string(),
      a.step_error_text(), r.wall_time_s, r.floor_s, r.overruns, out);
  if (!r.hold.empty()) {
    const std::optional<double> rms = instrument::hold_summary(r).path_error_rms_nm;
    fmt::print("hold: {} frames over {:.1f} s{}\n", r.hold.size(), m.params.hold_s,
               rms ? fmt::format(", the cavity's path from its set point {:.3f} nm RMS", *rms)
                   : std::string());
  }
  if (r.lock)
    fmt::print("lock: {} frames locked, {} without a pose ({} lost, {} taken again){}\n",
               r.lock->locked, r.lock->holding, r.lock->lost, r.lock->retaken,
               r.lock->first_refusal.empty() ? std::string() : "; first: " + r.lock->first_refusal);
}

int measure(MeasureOptions& o) {
  procedures::MeasureRequest& req = o.request;
  if (!o.steps_rad.empty())
    req.steps_rad = parse_list(o.steps_rad, "--steps-rad");
  procedures::MeasureOutcome m;
  {
    ProgressBar bar(1);
    m = procedures::run_measure(req, {.progress = bar.callback(), .stop_on_signals = true});
  }
  using procedures::MeasureEnd;
  if (m.end == MeasureEnd::kFault || m.end == MeasureEnd::kNotValid) {
    if (o.json)
      fmt::print("{}\n", procedures::measure_json(m).dump(2));
    if (m.end == MeasureEnd::kFault) {
      fmt::print(stderr, "piezoshift: {}\n", m.reason);
      return kExitFault;
    }
    throw rig::ProcedureFailed(m.reason);
  }
  if (m.end == MeasureEnd::kNoPupil || m.end == MeasureEnd::kNoPhase)
    throw rig::ProcedureFailed(m.reason);
  MeasureRecord rec = measure_record(m);
  if (m.end == MeasureEnd::kNotConverged) {
    if (o.json)
      fmt::print("{}\n", measure_json(rec).dump(2));
    throw rig::ProcedureFailed(m.reason);
  }
  write_measurement(rec, req.out);
  if (o.json)
    fmt::print("{}\n", measure_json(rec).dump(2));
  else
    print_summary(m, rec.out);
  return 0;
}

}  // namespace

void add_measure_command(CLI::App& app, Action& action) {
  auto o = std::make_shared<MeasureOptions>();
  procedures::MeasureRequest& q = o->request;
  CLI::App* cmd = app.add_subcommand(
      "measure",
      "Take a phase-shifting measurement: the stage steps through the shipping loop, the camera "
      "exposes once it has settled, then the analysis (docs/measure.md)");
  cmd->add_option("--camera", q.camera, "twin, files:DIR or aravis:ID (docs/camera.md)")
      ->capture_default_str();
  cmd->add_option("--daq", q.daq, "sim, or comedi:/dev/comediN")->capture_default_str();
  cmd->add_option("--rate-hz", q.rate_Hz, "loop rate, 1000 (the paper) to 10000 Hz")
      ->capture_default_str();
  cmd->add_option("--calibration", q.calibration_file,
                  "TOML with [controller] (the paper's or the improved controller)");
  cmd->add_option("--config", q.config_file,
                  "TOML configuration: the twin's sections, [safety] and [camera]");
  cmd->add_option("--algorithm", q.algorithm,
                  "4step, carre, hariharan5, degroot7, frame13, lsq, aia, tilt-aia")
      ->capture_default_str();
  cmd->add_option("--steps-rad", o->steps_rad,
                  "commanded steps, comma-separated, the first 0 (lsq, aia, tilt-aia)");
  cmd->add_option("--averages", q.averages, "measurements averaged, 1 to 100")
      ->capture_default_str()
      ->check(whole_number(instrument::kMinAverages, instrument::kMaxAverages));
  cmd->add_option("--surface", q.surface,
                  "the twin camera's test surface, as `psi simulate` takes it (Z4=40,rough=0.5)");
  cmd->add_option("--mask", q.mask_file,
                  "the pupil as a PNG (cameras other than the twin; the lock's too)");
  cmd->add_option("--base-um", q.base_um, "Z_d of P1..P3 at frame 0 (um)")->capture_default_str();
  cmd->add_option("--settle-band-nm", q.on_target.band_nm,
                  "settled: mean S - feedback within this on every channel (nm)")
      ->capture_default_str();
  cmd->add_option("--settle-hold-s", q.on_target.hold_s, "... averaged over this long (s)")
      ->capture_default_str();
  cmd->add_option("--settle-timeout-s", q.on_target.timeout_s,
                  "a step not settled by then ends the measurement (s)")
      ->capture_default_str();
  cmd->add_option("--frame-timeout-s", q.frame_timeout_s,
                  "a frame not arrived by then ends the measurement (s)")
      ->capture_default_str();
  add_physics_budget_option(cmd, q.max_physics_steps);
  cmd->add_option("--seed", q.seed, "twin and camera noise seed")
      ->capture_default_str()
      ->check(whole_number(0, kAnyUnsigned));
  cmd->add_option("--trigger", q.trigger,
                  "software (camera.trigger() between ticks) or line (a pulse on the DAQ's "
                  "trigger line written by the loop's tick; the camera's trigger source a line)")
      ->capture_default_str();
  cmd->add_option("--trigger-line", q.trigger_line,
                  "comedi: the trigger output as SUBDEVICE/CHANNEL (2/0: the PCI-6229's P0.0)");
  cmd->add_flag("--free-run", q.free_run,
                "sim only: simulated clock, as fast as possible (tests, benches)");
  cmd->add_option("--cpu", q.cpu, "CPU to pin the loop to (-1: the last one, -2: none)")
      ->capture_default_str();
  cmd->add_flag("--lock", q.lock,
                "hold the Fizeau cavity on the fringes (docs/fizeau.md): the first average's "
                "first four frames are the reference; the pupil: the twin camera's, --mask, "
                "else found in them (a calibration file's [controller] outer = \"fringes\" "
                "asks for it too, with its [fringe_lock])");
  cmd->add_option("--lock-retake-s", q.lock_retake_s,
                  "with --lock: a frame whose fringes were lost is taken again until they come "
                  "back, for at most this long (s, in (0, 60]); then the measurement fails")
      ->capture_default_str();
  cmd->add_option("--hold-s", q.hold_s,
                  "after the measurement, hold the stage at frame 0 for this long while the "
                  "camera exposes frame after frame (with --lock, the lock holds the cavity; "
                  "hold.csv, hold.png), 0 to 3600 s")
      ->capture_default_str();
  cmd->add_option("--out", q.out, "a new folder for the measurement")->required();
  cmd->add_flag("--json", o->json, "print the summary as JSON");
  cmd->callback([&action, o] { action = [o] { return measure(*o); }; });
}

}  // namespace piezoshift::app
