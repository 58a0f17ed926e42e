// `piezoshift psi simulate|analyze|calibrate`: phase-shifting interferometry (docs/psi.md).
//   simulate   the acquisition on the twin with the paper's controller, frames rendered from the
//              plate's true motion, analysed; the surface error the stage causes; a budget table
//   analyze    frames (8- or 16-bit PNG) to a surface map: surface_nm.npy, surface_nm.png,
//              surface_m.gsf and surface_nm.datx (with its lateral scale), JSON
//   compare    two maps (.gsf, .datx) of one part: the difference, its RMS, Zernike terms
//              (psi_compare.hpp)
//   calibrate  the steps the stage made, recovered from frames (AIA), as a TOML table
// Bad files, sizes, counts or values exit with status 2 and a message naming the file or option.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <numbers>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "piezoshift/camera/camera_config.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/core/bounds.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/core/wavelength.hpp"
#include "piezoshift/instrument/fringe_actuator_scan.hpp"
#include "piezoshift/io/atomic_file.hpp"
#include "piezoshift/psi/analysis.hpp"
#include "piezoshift/psi/error_budget.hpp"
#include "piezoshift/psi/frame_set.hpp"
#include "piezoshift/psi/npy.hpp"
#include "piezoshift/psi/png_image.hpp"
#include "piezoshift/psi/pupil_detection.hpp"
#include "piezoshift/psi/simulation.hpp"
#include "piezoshift/psi/step_calibration.hpp"
#include "piezoshift/psi/surface_datx.hpp"
#include "piezoshift/psi/surface_figure.hpp"
#include "piezoshift/psi/surface_file.hpp"
#include "piezoshift/psi/zernike.hpp"
#include "piezoshift/rig/validity.hpp"
#include "piezoshift/runtime/safety_ranges.hpp"
#include "psi_compare.hpp"
#include "psi_options.hpp"
#include "whole_number.hpp"

namespace piezoshift::app {
namespace {

using Json = nlohmann::ordered_json;
namespace fs = std::filesystem;

struct PsiOptions {
  // shared
  std::string out;
  bool json = false;
  std::string algorithm;
  double wavelength_nm = core::kHeNeWavelength_nm;
  // analyze, calibrate
  std::vector<std::string> frames;
  std::string mask;
  std::string steps_rad;
  bool remove_power = false;
  //! The pupil's radius on the plate, which sets the surface's lateral scale: [camera]'s.
  double pupil_radius_m = camera::CameraConfig{}.pupil_radius_m;
  double nominal_step_rad = std::numbers::pi / 2.0;
  // simulate
  std::string config;
  int n_frames = 0;
  std::string surface;
  std::uint64_t seed = 1;
  int size_px = 256;
  bool budget = true;
};

psi::Analysis run_analysis(const std::vector<psi::Map>& frames, const psi::Mask& mask,
                           psi::AnalysisOptions ao) {
  try {
    return psi::analyze_frames(frames, mask, ao);
  } catch (const std::invalid_argument& e) {
    throw core::InputError(fmt::format("psi: {}", e.what()));
  }
}

// The iterative fits' own check (aia, tilt-aia): why not converged, and the frames' residual
// from the fitted model and its white part, each over the median modulation.
void add_fit_check(Json& j, const psi::PhaseResult& r) {
  if (!std::isfinite(r.residual_rms))
    return;
  j["reason"] = r.reason;
  j["residual_rms"] = r.residual_rms;
  j["noise_rms"] = r.noise_rms;
  if (std::isfinite(r.step_conditioning))
    j["step_conditioning"] = r.step_conditioning;
}

// --pupil-radius-m against [camera] pupil_radius_m's range (camera_config.hpp), the one list.
void check_pupil_radius(double radius_m) {
  core::Bounds bounds;
  camera::CameraConfig config;
  camera::visit_camera_values(
      config, [&](std::string_view, std::string_view key, const auto&, const core::Bounds& b) {
        if (key == "pupil_radius_m")
          bounds = b;
      });
  if (const std::string problem = core::range_problem("--pupil-radius-m", radius_m, bounds);
      !problem.empty())
    throw core::InputError(problem);
}

// Writes surface_nm.npy and surface_nm.png into out, and surface_m.gsf and surface_nm.datx when
// m_per_px > 0 (the lateral scale, metres on the plate per pixel); returns the analysis's JSON.
Json write_analysis(const psi::Analysis& a, psi::Algorithm alg, double wavelength_nm,
                    const std::string& out, const Json& pupil = nullptr, double m_per_px = 0.0) {
  fs::create_directories(out);
  psi::write_npy((fs::path(out) / "surface_nm.npy").string(), a.surface_nm);
  if (m_per_px > 0.0) {
    const psi::ScaledSurface s{a.surface_nm, m_per_px, "surface, piston and tilt removed"};
    psi::write_gsf((fs::path(out) / "surface_m.gsf").string(), s);
    psi::write_datx((fs::path(out) / "surface_nm.datx").string(), s, wavelength_nm * 1e-9);
  }
  const auto [lo, hi] = psi::finite_range(a.surface_nm);
  psi::write_surface_map(
      fs::path(out) / "surface_nm.png", a.surface_nm, lo, hi,
      fmt::format("Surface, piston and tilt removed: RMS {:.2f} nm, PV {:.2f} nm", a.figures.rms,
                  a.figures.pv));
  Json j{{"algorithm", psi::algorithm_name(alg)}, {"wavelength_nm", wavelength_nm},
         {"frames", a.phase.steps_rad.size()},    {"steps_rad", a.phase.steps_rad},
         {"iterations", a.phase.iterations},      {"converged", a.phase.converged},
         {"valid_pixels", a.figures.pixels},      {"surface_rms_nm", a.figures.rms},
         {"surface_pv_nm", a.figures.pv},         {"surface_pvr_nm", a.figures.pvr},
         {"colour_scale_nm", {lo, hi}},           {"zernike_nm", a.zernike_nm}};
  add_fit_check(j, a.phase);
  if (!pupil.is_null())
    j["pupil"] = pupil;
  if (m_per_px > 0.0)
    j["lateral_scale_m_per_px"] = m_per_px;
  if (!a.phase.shifts.empty()) {
    const psi::FrameShiftColumns c = psi::shift_columns(a.phase.shifts);
    j["piston_rad"] = c.piston_rad;
    j["tip_rad"] = c.tip_rad;
    j["tilt_rad"] = c.tilt_rad;
  }
  io::write_file_atomically((fs::path(out) / "analysis.json").string(), j.dump(2) + "\n");
  return j;
}

void print_analysis(const psi::Analysis& a, psi::Algorithm alg, const std::string& out,
                    double m_per_px = 0.0) {
  fmt::print("algorithm {}  frames {}  valid pixels {}\n", psi::algorithm_name(alg),
             a.phase.steps_rad.size(), a.figures.pixels);
  std::string steps;
  for (const double s : a.phase.steps_rad)
    steps += fmt::format(" {:.4f}", s);
  fmt::print("steps [rad]:{}{}\n", steps,
             a.phase.iterations ? fmt::format("  ({} iterations{})", a.phase.iterations,
                                              a.phase.converged ? "" : ", not converged")
                                : std::string());
  fmt::print("surface: RMS {:.3f} nm  PV {:.3f} nm  PVr {:.3f} nm (piston and tilt removed)\n",
             a.figures.rms, a.figures.pv, a.figures.pvr);
  fmt::print("Zernike (Noll, nm RMS):");
  for (std::size_t j = 3; j < std::min<std::size_t>(a.zernike_nm.size(), 11); ++j)
    fmt::print(" Z{}={:.2f}", j + 1, a.zernike_nm[j]);
  fmt::print("\nwritten: {0}/surface_nm.npy {0}/surface_nm.png {0}/analysis.json", out);
  if (m_per_px > 0.0)
    fmt::print(" {0}/surface_m.gsf {0}/surface_nm.datx ({1:.6g} mm per pixel)", out,
               1e3 * m_per_px);
  fmt::print("\n");
}

int run_analyze(const PsiOptions& o) {
  check_wavelength(o.wavelength_nm);
  check_pupil_radius(o.pupil_radius_m);
  const std::vector<psi::Map> frames = psi::read_frame_set(o.frames);
  const psi::Algorithm alg = choose_algorithm(o.algorithm, frames.size());
  check_count(alg, frames.size());
  psi::AnalysisOptions ao;
  ao.phase.algorithm = alg;
  ao.wavelength_nm = o.wavelength_nm;
  ao.removal = o.remove_power ? psi::Removal::kTiltAndPower : psi::Removal::kTilt;
  if (!o.steps_rad.empty()) {
    ao.phase.steps_rad = parse_list(o.steps_rad, "--steps-rad");
    if (ao.phase.steps_rad.size() != frames.size())
      throw core::InputError(fmt::format("--steps-rad: {} values for {} frames",
                                         ao.phase.steps_rad.size(), frames.size()));
  }
  work_begins();  // the pupil, the phase and the surface of every pixel
  const PupilChoice pupil = choose_pupil(o.mask, frames, "psi");
  const psi::Analysis a = run_analysis(frames, pupil.mask, ao);
  if (!a.phase.converged) {  // not a surface: nothing written, exit 4
    if (o.json) {
      Json j{{"algorithm", psi::algorithm_name(alg)},
             {"steps_rad", a.phase.steps_rad},
             {"iterations", a.phase.iterations},
             {"converged", false}};
      add_fit_check(j, a.phase);
      j["pupil"] = pupil.json;
      fmt::print("{}\n", j.dump(2));
    }
    throw rig::ProcedureFailed(fmt::format("psi analyze: {}", a.phase.reason));
  }
  const double m_per_px = instrument::plate_m_per_px(pupil.mask, o.pupil_radius_m);
  Json pupil_json = pupil.json;
  pupil_json["radius_m"] = o.pupil_radius_m;
  const Json j = write_analysis(a, alg, o.wavelength_nm, o.out, pupil_json, m_per_px);
  if (o.json)
    fmt::print("{}\n", j.dump(2));
  else
    print_analysis(a, alg, o.out, m_per_px);
  return 0;
}

// The steps a frame set made, recovered by AIA, tilt-aia or Carre. Frames without fringes are
// refused as `psi analyze` refuses them (exit 2); a recovery that did not converge, or a gain
// that is not finite and positive, is not a calibration (exit 4, no file written).
psi::StepCalibration recover_steps(const PsiOptions& o, std::span<const psi::Map> frames,
                                   const psi::Mask& mask) {
  const psi::Algorithm alg =
      o.algorithm.empty() ? psi::Algorithm::kAia : psi::parse_algorithm(o.algorithm);
  if (alg != psi::Algorithm::kAia && alg != psi::Algorithm::kTiltAia &&
      alg != psi::Algorithm::kCarre)
    throw core::InputError(
        fmt::format("--algorithm {}: calibration needs aia, tilt-aia or carre", o.algorithm));
  check_count(alg, frames.size());
  psi::PhaseOptions po;
  po.algorithm = alg;
  for (std::size_t k = 0; k < frames.size(); ++k)
    po.steps_rad.push_back(static_cast<double>(k) * o.nominal_step_rad);
  psi::PhaseResult r;
  try {
    r = psi::wrapped_phase(frames, mask, po);
    psi::modulated_pixels(r, mask, psi::AnalysisOptions{});
  } catch (const std::invalid_argument& e) {
    throw core::InputError(fmt::format("psi calibrate: {}", e.what()));
  }
  psi::StepCalibration c = psi::calibrate_steps(r.steps_rad, o.nominal_step_rad, o.wavelength_nm);
  c.algorithm = std::string(psi::algorithm_name(alg));
  c.iterations = r.iterations;
  c.converged = r.converged;
  c.reason = r.reason;
  if (const std::string problem = psi::step_calibration_problem(c); !problem.empty()) {
    if (o.json)
      fmt::print("{}\n", Json{{"algorithm", c.algorithm},
                              {"iterations", c.iterations},
                              {"steps_rad", c.steps_rad},
                              {"converged", false},
                              {"reason", problem}}
                             .dump(2));
    throw rig::ProcedureFailed(fmt::format("psi calibrate: {}", problem));
  }
  return c;
}

int run_calibrate(const PsiOptions& o) {
  check_wavelength(o.wavelength_nm);
  if (!(o.nominal_step_rad >= psi::kMinNominalStepRad &&
        o.nominal_step_rad <= psi::kMaxNominalStepRad))
    throw core::InputError(fmt::format(
        "--nominal-step-rad {}: must be in [{:g}, pi - {:g}] = [{:g}, {:.4f}] rad",
        o.nominal_step_rad, psi::kMinNominalStepRad, std::numbers::pi - psi::kMaxNominalStepRad,
        psi::kMinNominalStepRad, psi::kMaxNominalStepRad));
  const std::vector<psi::Map> frames = psi::read_frame_set(o.frames);
  work_begins();  // the pupil, the steps' recovery, the file
  const PupilChoice pupil = choose_pupil(o.mask, frames, "psi calibrate");
  const psi::StepCalibration c = recover_steps(o, frames, pupil.mask);
  if (const fs::path parent = fs::path(o.out).parent_path(); !parent.empty())
    fs::create_directories(parent);
  io::write_file_atomically(o.out, psi::format_step_calibration_toml(c));
  if (o.json) {
    const Json j{{"algorithm", c.algorithm},
                 {"wavelength_nm", c.wavelength_nm},
                 {"nominal_step_rad", c.nominal_step_rad},
                 {"steps_rad", c.steps_rad},
                 {"steps_nm", c.steps_nm},
                 {"increments_nm", c.increments_nm},
                 {"step_gain", c.step_gain},
                 {"quadratic_per_rad", c.quadratic_per_rad},
                 {"nonlinearity_pct", c.nonlinearity_pct},
                 {"rms_step_error_rad", c.rms_step_error_rad},
                 {"iterations", c.iterations},
                 {"converged", c.converged},
                 {"reason", ""},
                 {"pupil", pupil.json},
                 {"calibration", o.out}};
    fmt::print("{}\n", j.dump(2));
  } else {
    fmt::print("steps recovered by {} from {} frames ({} iterations{})\n", c.algorithm,
               frames.size(), c.iterations, c.converged ? "" : ", not converged");
    for (std::size_t k = 0; k < c.steps_rad.size(); ++k)
      fmt::print("  frame {:2}  {:9.5f} rad  {:9.3f} nm   nominal {:9.3f} nm\n", k, c.steps_rad[k],
                 c.steps_nm[k], k * o.nominal_step_rad * o.wavelength_nm / (4 * std::numbers::pi));
    fmt::print("step gain {:.5f} (error {:+.3f} %)  nonlinearity {:.3f} % of span\n", c.step_gain,
               100.0 * (c.step_gain - 1.0), c.nonlinearity_pct);
    fmt::print("written: {}\n", o.out);
  }
  return 0;
}

int run_simulate(const PsiOptions& o) {
  config::ProjectConfig config;
  if (!o.config.empty())
    config = runtime::load_installation_config(o.config).project;  // [safety] allowed, unused
  psi::SimulationParams p;
  p.algorithm =
      o.algorithm.empty() ? psi::Algorithm::kHariharan5 : psi::parse_algorithm(o.algorithm);
  p.frames = o.n_frames;
  p.seed = o.seed;
  if (!o.surface.empty())
    p.surface = psi::parse_surface_spec(o.surface);
  if (o.size_px < 32 || o.size_px > 2048)
    throw core::InputError(fmt::format("--size {}: must be in 32..2048", o.size_px));
  p.fizeau.width_px = p.fizeau.height_px = o.size_px;
  p.fizeau.pupil_radius_px = 0.47 * o.size_px;
  p.fizeau.wavelength_nm = o.wavelength_nm;
  check_wavelength(o.wavelength_nm);
  work_begins();                             // the twin's stage and camera, the frames
  control::SemiClosedLoopParams controller;  // the paper's gains, A and p
  const psi::SimulationResult r = psi::simulate_psi(config, controller, p);

  fs::create_directories(o.out);
  const double msb = std::ldexp(1.0, 16 - p.camera.bit_depth);  // MSB-aligned in the 16-bit PNG
  for (std::size_t k = 0; k < r.frames.size(); ++k) {
    psi::Map f = r.frames[k];
    for (double& v : f.v)
      v *= msb;
    psi::write_png_gray16((fs::path(o.out) / fmt::format("frame_{:02}.png", k)).string(), f);
  }
  psi::write_mask_png((fs::path(o.out) / "mask.png").string(), r.mask);
  psi::write_npy((fs::path(o.out) / "surface_truth_nm.npy").string(), r.truth_nm);
  Json j = write_analysis(r.analysis, p.algorithm, p.fizeau.wavelength_nm, o.out);
  {
    std::string csv = "time_s,command_nm,gauge_error_nm,piston_nm,theta_x_urad,theta_y_urad\n";
    for (const psi::StageLogEntry& e : r.log)
      csv += fmt::format("{:.4f},{:.4f},{:.4f},{:.4f},{:.6f},{:.6f}\n", e.time_s, e.command_nm,
                         e.gauge_error_nm, e.truth.piston_nm, e.truth.theta_x_urad,
                         e.truth.theta_y_urad);
    io::write_file_atomically((fs::path(o.out) / "stage_log.csv").string(), csv);
    csv =
        "frame,move_time_s,on_target_time_s,on_target,exposure_start_s,step_nm,blur_nm,"
        "tip_urad,tilt_urad\n";
    for (std::size_t k = 0; k < r.frame_stats.size(); ++k) {
      const psi::FrameRecord& f = r.acquisition.frames[k];
      const psi::FrameStats& s = r.frame_stats[k];
      csv += fmt::format("{},{:.4f},{:.4f},{},{:.4f},{:.4f},{:.4f},{:.6f},{:.6f}\n", k,
                         f.move_time_s, f.on_target_time_s, f.on_target ? 1 : 0, f.exposure_start_s,
                         s.step_nm, s.blur_nm, s.tip_urad, s.tilt_urad);
    }
    io::write_file_atomically((fs::path(o.out) / "frames.csv").string(), csv);
  }
  psi::ErrorBudget budget;
  if (o.budget) {
    psi::BudgetParams bp;
    bp.wavelength_nm = p.fizeau.wavelength_nm;
    bp.seed = o.seed;
    budget = psi::error_budget(bp, psi::all_algorithms());
  }
  const double step_nominal =
      psi::nominal_step_rad(p.algorithm) * p.fizeau.wavelength_nm / (4.0 * std::numbers::pi);
  j["surface_error_rms_nm"] = r.error_rms_nm;
  j["ideal_stage_error_rms_nm"] = r.ideal_error_rms_nm;
  j["stage_error_rms_nm"] = r.stage_error_rms_nm;
  Json frames = Json::array();
  for (std::size_t k = 0; k < r.frame_stats.size(); ++k) {
    const psi::FrameStats& s = r.frame_stats[k];
    frames.push_back({{"step_nm", s.step_nm},
                      {"step_error_nm", s.step_nm - static_cast<double>(k) * step_nominal},
                      {"blur_nm", s.blur_nm},
                      {"tip_urad", s.tip_urad},
                      {"tilt_urad", s.tilt_urad},
                      {"settle_s", s.settle_s},
                      {"on_target", s.on_target}});
  }
  j["stage_frames"] = frames;
  if (o.budget) {
    Json rows = Json::array();
    for (const psi::BudgetRow& row : budget.rows)
      rows.push_back(
          {{"source", row.source}, {"magnitude", row.magnitude}, {"rms_nm", row.rms_nm}});
    Json names = Json::array();
    for (const psi::Algorithm a : budget.algorithms)
      names.push_back(psi::algorithm_name(a));
    j["budget"] = {{"algorithms", names}, {"rows", rows}};
  }
  io::write_file_atomically((fs::path(o.out) / "simulation.json").string(), j.dump(2) + "\n");
  if (o.json) {
    fmt::print("{}\n", j.dump(2));
    return 0;
  }
  fmt::print("PSI on the twin (paper's controller), {} frames of {} x {} px, seed {}\n",
             r.frames.size(), o.size_px, o.size_px, o.seed);
  fmt::print("frame  step [nm]  error [nm]  blur [nm]  tip [urad]  tilt [urad]  settle [ms]\n");
  for (std::size_t k = 0; k < r.frame_stats.size(); ++k) {
    const psi::FrameStats& s = r.frame_stats[k];
    fmt::print("{:5}  {:9.3f}  {:10.3f}  {:9.3f}  {:10.5f}  {:11.5f}  {:11.1f}{}\n", k, s.step_nm,
               s.step_nm - static_cast<double>(k) * step_nominal, s.blur_nm, s.tip_urad,
               s.tilt_urad, 1000.0 * s.settle_s, s.on_target ? "" : "  (not on target)");
  }
  print_analysis(r.analysis, p.algorithm, o.out);
  fmt::print(
      "surface error vs truth: {:.4f} nm RMS; with an ideal stage {:.4f} nm; "
      "caused by the stage {:.4f} nm\n",
      r.error_rms_nm, r.ideal_error_rms_nm, r.stage_error_rms_nm);
  if (o.budget)
    fmt::print("\nError budget (Monte Carlo, {} px pupil):\n{}", psi::BudgetParams{}.size_px,
               psi::format_budget_table(budget));
  return 0;
}

}  // namespace

void add_psi_command(CLI::App& app, Action& action) {
  CLI::App* psi = app.add_subcommand(
      "psi", "Phase-shifting interferometry: simulate, analyze, calibrate, compare (docs/psi.md)");
  psi->require_subcommand(1);
  auto o = std::make_shared<PsiOptions>();
  const std::string names = "4step, carre, hariharan5, degroot7, frame13, lsq, aia, tilt-aia";

  CLI::App* sim = psi->add_subcommand(
      "simulate", "Acquire on the twin, render Fizeau frames, analyse them, report the errors");
  sim->add_option("--out", o->out, "Output folder")->required();
  sim->add_option("--config", o->config, "Project configuration (TOML)");
  sim->add_option("--frames", o->n_frames, "Frames (default: the algorithm's count, else 5)");
  sim->add_option("--algorithm", o->algorithm, "One of " + names + " (default hariharan5)");
  sim->add_option("--surface", o->surface, "Test surface, e.g. Z4=40,Z5=25,rough=0.5 (nm)");
  sim->add_option("--seed", o->seed, "Random seed")
      ->capture_default_str()
      ->check(whole_number(0, kAnyUnsigned));
  sim->add_option("--size", o->size_px, "Camera size [px], square")->capture_default_str();
  sim->add_option("--wavelength-nm", o->wavelength_nm, "Wavelength [nm]")->capture_default_str();
  sim->add_flag("!--no-budget", o->budget, "Skip the Monte Carlo error budget");
  sim->add_flag("--json", o->json, "Machine-readable output");

  CLI::App* ana = psi->add_subcommand("analyze", "Frames (PNG) to a surface map");
  ana->add_option("frames", o->frames, "Frames in acquisition order (8- or 16-bit PNG)")
      ->required();
  ana->add_option("--mask", o->mask, "Pupil mask PNG (nonzero inside)");
  ana->add_option("--algorithm", o->algorithm,
                  "One of " + names +
                      " (default by count: 4 4step, 5 hariharan5, 7 degroot7, "
                      "13 frame13, else lsq)");
  ana->add_option("--steps-rad", o->steps_rad, "Known steps for lsq, e.g. 0,1.57,3.14,4.71");
  ana->add_option("--wavelength-nm", o->wavelength_nm, "Wavelength [nm]")->capture_default_str();
  ana->add_flag("--remove-power", o->remove_power, "Remove power (Z4) as well as piston and tilt");
  ana->add_option("--pupil-radius-m", o->pupil_radius_m,
                  "The pupil's radius on the plate [m]: the lateral scale of the .gsf and .datx")
      ->capture_default_str();
  ana->add_option("--out", o->out, "Output folder")->required();
  ana->add_flag("--json", o->json, "Machine-readable output");

  CLI::App* cal = psi->add_subcommand("calibrate", "Phase steps recovered from frames (TOML)");
  cal->add_option("frames", o->frames, "Frames in acquisition order (8- or 16-bit PNG)")
      ->required();
  cal->add_option("--mask", o->mask, "Pupil mask PNG (nonzero inside)");
  cal->add_option("--algorithm", o->algorithm, "aia (default), tilt-aia or carre");
  cal->add_option("--nominal-step-rad", o->nominal_step_rad, "Nominal step [rad]")
      ->capture_default_str();
  cal->add_option("--wavelength-nm", o->wavelength_nm, "Wavelength [nm]")->capture_default_str();
  cal->add_option("--out", o->out, "Calibration file to write (TOML)")->required();
  cal->add_flag("--json", o->json, "Machine-readable output");

  auto c = std::make_shared<PsiCompareOptions>();
  CLI::App* cmp = psi->add_subcommand(
      "compare", "Two surface maps (.gsf, .datx) of one part: B - A, its RMS and Zernike terms");
  cmp->add_option("a", c->a, "Map A (Gwyddion Simple Field .gsf, or Zygo .datx)")->required();
  cmp->add_option("b", c->b, "Map B (.gsf or .datx), the same size and lateral scale")->required();
  cmp->add_option("--out", c->out, "Folder for difference_m.gsf and comparison.json");
  cmp->add_flag("--json", c->json, "Machine-readable output");

  sim->callback([o, &action] { action = [o] { return run_simulate(*o); }; });
  cmp->callback([c, &action] { action = [c] { return run_psi_compare(*c); }; });
  ana->callback([o, &action] { action = [o] { return run_analyze(*o); }; });
  cal->callback([o, &action] { action = [o] { return run_calibrate(*o); }; });
}

}  // namespace piezoshift::app
