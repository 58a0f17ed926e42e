#include "calibrate_fizeau.hpp"

#include <fmt/core.h>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "improved_summary.hpp"
#include "paper_summary.hpp"
#include "physics_budget.hpp"
#include "piezoshift/calibration/calibration_cost.hpp"
#include "piezoshift/calibration/calibration_file.hpp"
#include "piezoshift/calibration/improved_calibration.hpp"
#include "piezoshift/camera/instrument_config.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/instrument/fringe_calibration.hpp"
#include "piezoshift/psi/fizeau_simulation.hpp"
#include "piezoshift/rig/validity.hpp"
#include "progress_bar.hpp"

namespace piezoshift::app {

namespace {

nlohmann::json outcome_json(const FizeauCalibrateRequest& q,
                            const instrument::FringeCalibrationOutcome& r) {
  nlohmann::json j = paper_calibration_json(r.controller, r.matrix, r.polynomial);
  j["calibration_file"] = q.out;
  j["interferometer"] = "fizeau";
  j["camera"] = "twin";
  j["p_points"] = r.polynomial.command_um.size();
  j["p_skipped_commands"] = r.polynomial.saturated_points;
  j["frames"] = instrument::frames_read(r);
  j["stage2_simulated_s"] = r.stage2_simulated_s;
  j["stage3_simulated_s"] = r.stage3_simulated_s;
  j["wall_s"] = r.wall_time_s;
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

}  // namespace

int calibrate_from_fringes_command(const FizeauCalibrateRequest& q) {
  if (!q.camera.empty() && q.camera != "twin")
    throw core::InputError(fmt::format(
        "--camera {}: the calibration from fringes runs on the twin's bench with the twin camera "
        "only (--camera twin); aravis:ID and files:DIR need the scans on a hardware loop, which "
        "is not built",
        q.camera));
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
  if (q.controller == "improved")
    return improved_from_fringes(q, ic, surface, fo);
  instrument::FringeCalibrationOutcome r;
  {
    ProgressBar bar(3);
    r = instrument::calibrate_twin_from_fringes(ic, q.seed, surface, fo, bar.callback());
  }
  if (!r.validity.valid)
    throw rig::ProcedureFailed("calibrate --interferometer fizeau: " + r.validity.reason +
                               "; no calibration file written");
  // No [travel]: Section 4.1's travel search reads the XL-80; `run` and `serve` then take the
  // paper's travel (calibration_file.hpp).
  calibration::write_calibration_file(
      q.out, r.controller,
      fmt::format("piezoshift calibration, identified on the digital twin by `piezoshift "
                  "calibrate --interferometer fizeau --camera twin`\ninterferometer: the Fizeau's "
                  "fringes (psi::FringeTracker, {} frames), not the XL-80; no optics moved\n"
                  "seed {}, configuration: {}, PID gains: {}",
                  instrument::frames_read(r), q.seed,
                  q.config.empty() ? "built-in defaults" : q.config,
                  q.pid == "paper" ? "the paper's" : "searched"));
  if (q.json) {
    fmt::print("{}\n", outcome_json(q, r).dump(2));
    return 0;
  }
  print_fringe_stages(r);
  fmt::print("written: {} (no [travel]: its search reads the XL-80)\n", q.out);
  return 0;
}

}  // namespace piezoshift::app
