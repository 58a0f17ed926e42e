#include "calibrate_fizeau.hpp"

#include <fmt/core.h>

#include <memory>
#include <optional>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "improved_summary.hpp"
#include "physics_budget.hpp"
#include "piezoshift/calibration/calibration_cost.hpp"
#include "piezoshift/calibration/calibration_file.hpp"
#include "piezoshift/calibration/improved_calibration.hpp"
#include "piezoshift/camera/instrument_config.hpp"
#include "piezoshift/camera/make_camera.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/instrument/fringe_calibration.hpp"
#include "piezoshift/instrument/loop_scan_stage.hpp"
#include "piezoshift/plant/geometry.hpp"
#include "piezoshift/procedures/calibration_json.hpp"
#include "piezoshift/procedures/loop_rig_stack.hpp"
#include "piezoshift/psi/fizeau_simulation.hpp"
#include "piezoshift/rig/validity.hpp"
#include "progress_bar.hpp"
#include "psi_options.hpp"

namespace piezoshift::app {

namespace {

nlohmann::json outcome_json(const FizeauCalibrateRequest& q,
                            const instrument::FringeCalibrationOutcome& r) {
  nlohmann::json j = procedures::fringe_calibration_json(r);
  j["calibration_file"] = q.out;
  j["interferometer"] = "fizeau";
  j["camera"] = q.camera.empty() ? "twin" : q.camera;
  j["daq"] = q.daq.empty() ? "bench" : q.daq;
  return j;
}

void print_fringe_stages(const instrument::FringeCalibrationOutcome& r) {
  const auto& g = r.controller.gains;
  const auto& p = r.controller.polynomial;
  fmt::print("stage 1  PID gains  kp {:g}, ki {:g}, kd {:g}\n", g.kp, g.ki, g.kd);
  fmt::print(
      "stage 2  matrix A from fringes (3 actuator scans, {:.1f} s simulated), cond(A) {:.3f}\n",
      r.stage2_simulated_s, r.matrix.fit.condition_number);
  for (const auto& row : r.controller.matrix.a)
    fmt::print("           [{:8.4f} {:8.4f} {:8.4f}]\n", row[0], row[1], row[2]);
  fmt::print(
      "stage 3  cubic p from fringes ({} frames, {:.1f} s simulated)  p3 {:.4e}, p2 {:.4e}, p1 "
      "{:.5f}, p0 {:.4f} um (rms {:.4f} um)\n",
      r.polynomial.command_um.size(), r.stage3_simulated_s, p.p3, p.p2, p.p1, p.p0,
      r.polynomial.fit.rms_residual_um);
}

// The improved controller around the stages from fringes (calibrate_improved's static-map hook):
// stage 0 and stage 4 read the gauges; stages 5 and 7 need the XL-80's dynamic samples, which no
// camera replaces, so no mode is nulled and the slew path is not tried.
int improved_from_fringes(const FizeauCalibrateRequest& q, const camera::InstrumentConfig& ic,
                          const psi::SurfaceSpec& surface,
                          const instrument::FringeCalibrationOptions& fo) {
  if (q.pid != "paper")
    throw core::InputError("--pid search: the improved controller has no PID to search");
  const config::ProjectConfig& config = ic.installation.project;
  control::SemiClosedLoopParams base;
  base.sample_time_s = config.twin.daq.sample_time_s;
  calibration::ImprovedCalibrationOptions io;
  io.paper.limits = ic.installation.safety;
  io.dynamic_interferometer = false;
  instrument::FringeCalibrationOutcome r;
  calibration::ImprovedCalibrationOutcome c;
  {
    ProgressBar bar(3);
    c = calibration::calibrate_improved(
        config, base, q.seed, io, [&](const calibration::CalibrationOptions& stages) {
          instrument::FringeCalibrationOptions f = fo;
          f.stages.holding_gains = stages.holding_gains;
          r = instrument::calibrate_twin_from_fringes(ic, q.seed, surface, f, bar.callback());
          if (!r.validity.valid)
            throw rig::ProcedureFailed("calibrate --interferometer fizeau --controller improved: " +
                                       r.validity.reason + "; no calibration file written");
          return r.controller;
        });
  }
  calibration::write_calibration_file(
      q.out, c.controller,
      fmt::format("piezoshift calibration of the improved controller, identified on the digital "
                  "twin by `piezoshift calibrate --interferometer fizeau --controller improved "
                  "--camera twin`\nA and p from the Fizeau's fringes ({} frames), no optics "
                  "moved; no plate mode nulled (no laser interferometer)\nseed {}, "
                  "configuration: {}",
                  instrument::frames_read(r), q.seed,
                  q.config.empty() ? "built-in defaults" : q.config));
  const ImprovedSummary summary{c.controller.improved, c.model, c.mode, c.shaped, &c.large_move};
  if (q.json) {
    nlohmann::json j = outcome_json(q, r);
    j.update(improved_json(summary));
    j["controller"] = "improved";
    fmt::print("{}\n", j.dump(2));
    return 0;
  }
  print_fringe_stages(r);
  print_improved(summary);
  fmt::print("written: {} (no [travel]: its search reads the XL-80)\n", q.out);
  return 0;
}

// The file `calibrate` writes, its header naming the Fizeau as the source, or nothing when the
// calibration failed (rig::ProcedureFailed). No [travel]: Section 4.1's travel search reads the
// XL-80; `run` and `serve` then take the paper's travel (calibration_file.hpp).
void write_fringe_calibration(const FizeauCalibrateRequest& q,
                              const instrument::FringeCalibrationOutcome& r,
                              const std::string& identified_by, const std::string& pupil) {
  if (!r.validity.valid)
    throw rig::ProcedureFailed("calibrate --interferometer fizeau: " + r.validity.reason +
                               "; no calibration file written");
  calibration::write_calibration_file(
      q.out, r.controller,
      fmt::format("piezoshift calibration, {}\ninterferometer: the Fizeau's fringes "
                  "(psi::FringeTracker, {} frames, pupil: {}), not the XL-80; no optics moved\n"
                  "seed {}, configuration: {}, PID gains: {}",
                  identified_by, instrument::frames_read(r), pupil, q.seed,
                  q.config.empty() ? "built-in defaults" : q.config,
                  q.pid == "paper" ? "the paper's" : "searched"));
}

// What the request cannot do, refused before anything runs.
void check_request(const FizeauCalibrateRequest& q) {
  const std::string& c = q.camera;
  if (c.starts_with("files:"))
    throw core::InputError(fmt::format(
        "--camera {}: recorded frames carry no record of the stage's motion while they were "
        "taken, and the calibration pairs every frame with the gauges at its exposure; run it "
        "with the camera on the stage (twin, aravis:ID)",
        c));
  if (!c.empty() && c != "twin" && !c.starts_with("aravis:"))
    throw core::InputError(
        fmt::format("--camera {}: expected twin or aravis:ID (docs/fizeau.md)", c));
  const bool loop = !q.daq.empty();
  if (loop && q.daq != "sim-rt" && q.daq != "comedi" && !q.daq.starts_with("comedi:"))
    throw core::InputError(fmt::format(
        "--interferometer fizeau with --daq {}: expected sim-rt or comedi:/dev/comediN (no "
        "--daq: the twin's bench on a simulated clock)",
        q.daq));
  if (!loop && c.starts_with("aravis:"))
    throw core::InputError(
        fmt::format("--camera {}: a real camera needs the stage on the real-time loop (--daq "
                    "comedi:/dev/comediN, or sim-rt for the twin)",
                    c));
  if (loop && (c.empty() || c == "twin") && q.daq != "sim-rt")
    throw core::InputError(fmt::format(
        "--camera twin renders the twin's plate: it needs --daq sim-rt, not {}", q.daq));
  const bool twin_fringes =
      c.empty() || c == "twin" || (c.starts_with("aravis:Fake") && q.daq == "sim-rt");
  if (!q.surface.empty() && !twin_fringes)
    throw core::InputError(
        "--surface: the test surface of the twin camera (or of aravis:Fake_1 on --daq sim-rt)");
  if (loop && q.controller != "paper")
    throw core::InputError(
        "--controller improved with --daq: the improved identification runs on the twin's "
        "bench only (no --daq)");
  if (loop && q.pid != "paper")
    throw core::InputError(
        "--pid search with --daq: the gain search scores the plate between the ticks, which a "
        "bench cannot see; the paper's gains are kept");
  if (q.free_run && q.daq != "sim-rt")
    throw core::InputError(fmt::format("--free-run needs --daq sim-rt{}",
                                       loop ? " (--daq " + q.daq + " is hardware)" : ""));
  if (!loop && !q.mask.empty())
    throw core::InputError("--mask: the twin's bench takes its scene's pupil (use --daq)");
  // It used to be ignored: the twin camera analyses the pupil it renders.
  if (loop && (c.empty() || c == "twin") && !q.mask.empty())
    throw core::InputError(
        "--mask: the twin camera renders its own pupil and analyses it; --mask is the pupil of "
        "other cameras");
}

// The stages on the real-time loop (rig::LoopRig) with the camera on it: the twin (sim-rt), with
// the twin camera or Aravis's fake camera shown its fringes, or a board and a real camera.
int fringes_on_loop(const FizeauCalibrateRequest& q, const camera::InstrumentConfig& ic,
                    const psi::SurfaceSpec& surface,
                    const instrument::FringeCalibrationOptions& fo) {
  const config::ProjectConfig& config = ic.installation.project;
  const std::string spec = q.camera.empty() ? "twin" : q.camera;
  std::optional<camera::TwinScene> scene;
  if (q.daq == "sim-rt")
    scene = camera::make_twin_scene(
        surface,
        camera::measurement_optics(ic.camera.settings, ic.camera.pupil_radius_m, fo.wavelength_nm),
        q.seed);
  const std::unique_ptr<camera::Camera> cam =
      camera::make_camera(spec, ic.camera, scene ? &*scene : nullptr);
  instrument::FringeOptics optics;
  optics.pupil_radius_m = ic.camera.pupil_radius_m;
  if (spec == "twin") {
    optics = instrument::twin_optics(*scene);
  } else if (!q.mask.empty()) {
    const camera::CameraSettings& cs = cam->settings();
    optics.mask = read_mask_of_size(q.mask, cs.width_px, cs.height_px, "the camera's frames");
    if (optics.mask.count() < 16)
      throw core::InputError(fmt::format("{}: the mask holds {} pixels (16 or more needed)", q.mask,
                                         optics.mask.count()));
    optics.plate_m_per_px = instrument::plate_m_per_px(optics.mask, optics.pupil_radius_m);
  }
  control::SemiClosedLoopParams base;
  base.sample_time_s = config.twin.daq.sample_time_s;
  procedures::LoopRigStack stack(
      {.daq = q.daq, .free_run = q.free_run, .seed = q.seed, .config_path = q.config},
      ic.installation, base);
  instrument::LoopScanStage stage(stack.rig(), plant::make_twin_geometry(config.twin.geometry));
  instrument::FringeCalibrationOutcome r;
  {
    ProgressBar bar(3);
    r = instrument::calibrate_from_fringes(stage, *cam, optics, fo, bar.callback());
  }
  const runtime::LoopResult loop = stack.rig().stop();
  write_fringe_calibration(
      q, r,
      fmt::format("identified by `piezoshift calibrate --interferometer fizeau --daq {} --camera "
                  "{}`",
                  q.daq, spec),
      r.pupil_from_modulation ? "found in the fringes' modulation"
                              : (q.mask.empty() ? "the twin's scene" : q.mask));
  const runtime::LoopStats& st = stack.rig().loop_stats();
  if (q.json) {
    nlohmann::json j = outcome_json(q, r);
    j["loop"] = {{"ticks", loop.ticks},
                 {"overruns", st.overruns},
                 {"max_consecutive_overruns", st.max_consecutive_overruns},
                 {"host_samples_dropped", loop.host_samples_dropped}};
    fmt::print("{}\n", j.dump(2));
    return 0;
  }
  print_fringe_stages(r);
  fmt::print("loop     {} ticks, {} overruns (at most {} in a row)\n", loop.ticks, st.overruns,
             st.max_consecutive_overruns);
  fmt::print("written: {} (no [travel]: its search reads the XL-80)\n", q.out);
  return 0;
}

}  // namespace

int calibrate_from_fringes_command(const FizeauCalibrateRequest& q) {
  check_request(q);
  const camera::InstrumentConfig ic =
      q.config.empty() ? camera::InstrumentConfig{} : camera::load_instrument_config(q.config);
  const psi::SurfaceSpec surface =
      q.surface.empty() ? psi::SurfaceSpec{} : psi::parse_surface_spec(q.surface);
  const config::ProjectConfig& config = ic.installation.project;
  const instrument::FringeCalibrationOptions fo =
      instrument::fringe_calibration_options(q.pid == "search", ic.installation.safety);
  // The XL-80's stages bound the scans' (docs/fizeau.md) and the travel it adds is not run
  // here: the check errs on the safe side.
  // The improved identification's: the XL-80 path's whole cost, its travel and stages 5 and 7
  // included, again on the safe side.
  check_procedure_cost("calibrate --interferometer fizeau",
                       q.controller == "improved" ? calibration::improved_calibration_cost()
                                                  : calibration::calibration_cost(
                                                        fo.stages, config.twin.daq.sample_time_s),
                       config.twin, q.max_physics_steps);
  work_begins();  // the twin's scene, the stage, the camera
  if (!q.daq.empty())
    return fringes_on_loop(q, ic, surface, fo);
  if (q.controller == "improved")
    return improved_from_fringes(q, ic, surface, fo);
  instrument::FringeCalibrationOutcome r;
  {
    ProgressBar bar(3);
    r = instrument::calibrate_twin_from_fringes(ic, q.seed, surface, fo, bar.callback());
  }
  write_fringe_calibration(
      q, r,
      "identified on the digital twin by `piezoshift calibrate --interferometer fizeau --camera "
      "twin`",
      "the twin's scene");
  if (q.json) {
    fmt::print("{}\n", outcome_json(q, r).dump(2));
    return 0;
  }
  print_fringe_stages(r);
  fmt::print("written: {} (no [travel]: its search reads the XL-80)\n", q.out);
  return 0;
}

}  // namespace piezoshift::app
