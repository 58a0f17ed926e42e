// `piezoshift calibrate`: the paper's three calibration stages on the twin, or guided on a bench
// (--daq, --interferometer: calibration/guided_calibration.hpp), or with the Fizeau's fringes as
// the interferometer, on the twin or the loop (--interferometer fizeau: calibrate_fizeau.hpp),
// written as a
// calibration file that `piezoshift run --calibration` loads.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "calibrate_fizeau.hpp"
#include "command.hpp"
#include "improved_summary.hpp"
#include "paper_summary.hpp"
#include "physics_budget.hpp"
#include "piezoshift/calibration/calibration_cost.hpp"
#include "piezoshift/calibration/calibration_file.hpp"
#include "piezoshift/calibration/calibration_procedure.hpp"
#include "piezoshift/calibration/guided_calibration.hpp"
#include "piezoshift/calibration/guided_session.hpp"
#include "piezoshift/calibration/improved_calibration.hpp"
#include "piezoshift/calibration/interferometer_source.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/experiments/paper_experiments.hpp"
#include "piezoshift/io/csv_writer.hpp"
#include "piezoshift/procedures/loop_rig_stack.hpp"
#include "piezoshift/procedures/loop_setup.hpp"
#include "piezoshift/rig/bench.hpp"
#include "piezoshift/rig/guided_rig.hpp"
#include "piezoshift/rig/loop_rig.hpp"
#include "piezoshift/runtime/safety_ranges.hpp"
#include "progress_bar.hpp"
#include "whole_number.hpp"

namespace piezoshift::app {
namespace {

struct Options {
  double max_physics_steps = plant::kDefaultPhysicsStepBudget;
  std::string out = "calibration.toml";
  std::uint64_t seed = 1;
  std::string config;
  std::string pid = "paper";
  std::string controller = "paper";
  bool json = false;
  std::string daq;             //!< guided: sim or comedi[:DEVICE]
  std::string interferometer;  //!< guided: prompt, file:PATH or sim; or fizeau (the fringes)
  std::string camera;          //!< --interferometer fizeau: twin
  std::string surface;         //!< --interferometer fizeau: the twin camera's test surface
  std::string mask;            //!< --interferometer fizeau --daq: the pupil as a PNG
  bool free_run = false;       //!< guided, sim-rt: the loop paced by the procedure
  bool restart = false;
  double max_zero_drift_um = calibration::GuidedOptions{}.max_zero_drift_um;
};

std::string session_path(const std::string& out) {
  return std::filesystem::path(out).replace_extension(".session.json").string();
}

void print_fits(const control::SemiClosedLoopParams& controller,
                const calibration::MatrixIdentificationResult& matrix,
                const calibration::PolynomialIdentificationResult& polynomial) {
  fmt::print("stage 2  matrix A   rms residual {:.4f} um, cond(A) {:.3f}\n",
             matrix.fit.rms_residual_um, matrix.fit.condition_number);
  for (const auto& row : controller.matrix.a) {
    fmt::print("           [{:8.4f} {:8.4f} {:8.4f}]\n", row[0], row[1], row[2]);
  }
  const auto& p = controller.polynomial;
  fmt::print("stage 3  cubic p    p3 {:.4e}, p2 {:.4e}, p1 {:.5f}, p0 {:.4f} um (rms {:.4f} um)\n",
             p.p3, p.p2, p.p1, p.p0, polynomial.fit.rms_residual_um);
}

// The guided calibration: the poses through the one control tick, the readings from the
// operator, a log file or the twin's interferometer, the session recorded beside --out.
void check_guided_options(const Options& o) {
  if (o.pid != "paper")
    throw core::InputError(
        "--pid search: the guided calibration keeps the paper's gains (the search scores the "
        "plate's motion between the ticks, which a bench does not see)");
  const bool sim = o.daq == "sim";
  const bool sim_rt = o.daq == "sim-rt";
  const bool comedi = o.daq == "comedi" || o.daq.rfind("comedi:", 0) == 0;
  if (!sim && !sim_rt && !comedi)
    throw core::InputError(
        fmt::format("--daq {}: expected sim, sim-rt or comedi:/dev/comediN", o.daq));
  if (o.free_run && !sim_rt)
    throw core::InputError(fmt::format(
        "--free-run needs --daq sim-rt (--daq {} {})", o.daq,
        sim ? "runs on a simulated clock already" : "runs in real time: it is hardware"));
  const std::string& ifm = o.interferometer;
  if (ifm.empty())
    throw core::InputError("--daq needs --interferometer prompt, file:PATH or sim");
  if (ifm != "prompt" && ifm != "sim" && !(ifm.rfind("file:", 0) == 0 && ifm.size() > 5))
    throw core::InputError(
        fmt::format("--interferometer {}: expected prompt, file:PATH or sim", ifm));
  if (comedi && ifm == "sim")
    throw core::InputError(
        fmt::format("--interferometer sim: the twin's interferometer does not see the stage on "
                    "--daq {}; give prompt or file:PATH",
                    o.daq));
  if (!(o.max_zero_drift_um > 0.0))
    throw core::InputError(
        fmt::format("--max-zero-drift-um {}: must be a positive length", o.max_zero_drift_um));
}

// The session to continue: the one recorded in session_file for the same plan (unless
// --restart), else a new one.
calibration::GuidedSession open_session(const Options& o, const std::string& session_file,
                                        const std::string& plan_text, std::size_t steps) {
  calibration::GuidedSession session{plan_text, steps, {}};
  if (o.restart)
    return session;
  if (auto loaded = calibration::load_guided_session(session_file)) {
    if (loaded->plan != plan_text || loaded->steps != steps)
      throw core::InputError(fmt::format(
          "{}: this session was recorded for \"{}\", not \"{}\": give --restart to discard it",
          session_file, loaded->plan, plan_text));
    session = std::move(*loaded);
    fmt::print(stderr, "resuming {}: {} of {} steps recorded\n", session_file,
               session.readings.size(), steps);
  }
  return session;
}

std::unique_ptr<calibration::InterferometerSource> make_source(
    const std::string& ifm, const std::function<void(const std::string&)>& say) {
  if (ifm == "prompt")
    return std::make_unique<calibration::PromptSource>(std::cin, say);
  if (ifm == "sim")
    return std::make_unique<calibration::TwinSource>();
  return std::make_unique<calibration::LogFileSource>(ifm.substr(5));
}

// The rigs the two stages run on: on --daq sim the twin on a simulated clock (stage 2 on
// seed + 1, stage 3 on seed + 2, as `calibrate` on the twin); otherwise one rig on the
// real-time loop (the shared loop stack) in a thread of its own, for both stages.
class GuidedRigs {
 public:
  GuidedRigs(const Options& o, const runtime::InstallationConfig& installation,
             const control::SemiClosedLoopParams& base) {
    const config::ProjectConfig& config = installation.project;
    const double window_s = config.twin.interferometer.static_average_s;
    if (o.daq == "sim") {
      const rig::BenchOptions bo{rig::Feedback::kGauges, installation.safety};
      bench2_ = std::make_unique<rig::Bench>(config, base, o.seed + 1, bo);
      bench3_ = std::make_unique<rig::Bench>(config, base, o.seed + 2, bo);
      bench_rig2_ = std::make_unique<rig::BenchRig>(*bench2_, window_s);
      bench_rig3_ = std::make_unique<rig::BenchRig>(*bench3_, window_s, bench_rig2_.get());
      rig2_ = bench_rig2_.get();
      rig3_ = bench_rig3_.get();
      return;
    }
    loop_ = std::make_unique<procedures::LoopRigStack>(
        procedures::LoopRigStackOptions{.daq = o.daq,
                                        .free_run = o.free_run,
                                        .seed = o.seed,
                                        .config_path = o.config,
                                        .window_s = window_s},
        installation, base);
    loop_rig_ = &loop_->rig();
    rig2_ = loop_rig_;
    rig3_ = loop_rig_;
  }

  rig::GuidedRig& stage2() { return *rig2_; }
  rig::GuidedRig& stage3() { return *rig3_; }
  //! The real-time loop's rig, or null on the simulated bench.
  rig::LoopRig* loop_rig() { return loop_rig_; }

 private:
  std::unique_ptr<rig::Bench> bench2_, bench3_;
  std::unique_ptr<rig::BenchRig> bench_rig2_, bench_rig3_;
  std::unique_ptr<procedures::LoopRigStack> loop_;
  rig::LoopRig* loop_rig_ = nullptr;
  rig::GuidedRig* rig2_ = nullptr;
  rig::GuidedRig* rig3_ = nullptr;
};

struct FitDataFiles {
  std::string poses;
  std::string points;
};

// The data of the two fits, in the formats `fit matrix|poly --data` read (docs/files.md), so that
// A and p can be fitted again from them (or from a part of them).
FitDataFiles write_fit_data(const std::string& out, const calibration::GuidedOutcome& r,
                            const std::string& session_file) {
  const std::filesystem::path folder = std::filesystem::path(out).parent_path();
  const FitDataFiles files{(folder / "matrix_poses.csv").string(),
                           (folder / "polynomial_points.csv").string()};
  constexpr auto kAtomic = io::CsvWriter::Mode::kReplaceAtomically;
  io::CsvWriter poses(files.poses, {"s1_um", "s2_um", "s3_um", "z1_um", "z2_um", "z3_um"}, 9,
                      kAtomic);
  poses.comment(
      fmt::format("guided calibration stage 2: poses (dS, dZ), session {}", session_file));
  for (std::size_t k = 0; k < r.matrix.ds_um.size(); ++k) {
    const control::Vec3& ds = r.matrix.ds_um[k];
    const control::Vec3& dz = r.matrix.dz_um[k];
    poses.row({ds[0], ds[1], ds[2], dz[0], dz[1], dz[2]});
  }
  poses.close();
  io::CsvWriter points(files.points, {"command_um", "measured_um"}, 9, kAtomic);
  points.comment(
      fmt::format("guided calibration stage 3: commands and readings, session {}", session_file));
  for (std::size_t k = 0; k < r.polynomial.command_um.size(); ++k)
    points.row({r.polynomial.command_um[k], r.polynomial.measured_um[k]});
  points.close();
  return files;
}

nlohmann::json guided_json(const Options& o, const calibration::GuidedOutcome& r,
                           const FitDataFiles& files, const std::string& session_file,
                           std::size_t steps) {
  nlohmann::json j = paper_calibration_json(r.controller, r.matrix, r.polynomial);
  j["calibration_file"] = o.out;
  j["session_file"] = session_file;
  j["matrix_poses_file"] = files.poses;
  j["polynomial_points_file"] = files.points;
  j["readings_taken"] = r.taken;
  j["steps"] = steps;
  j["p_skipped_commands"] = r.polynomial.saturated_points;
  return j;
}

int run_guided(const Options& o) {
  check_guided_options(o);
  const runtime::InstallationConfig installation =
      o.config.empty() ? runtime::InstallationConfig{}
                       : runtime::load_installation_config(o.config);
  const config::ProjectConfig& config = installation.project;
  work_begins();  // the session file, the interferometer, the stage
  calibration::GuidedOptions go;
  go.max_zero_drift_um = o.max_zero_drift_um;
  const std::vector<calibration::GuidedStep> plan = calibration::guided_plan(go);
  const std::string session_file = session_path(o.out);
  const std::string plan_text = fmt::format(
      "daq {}, seed {}, configuration {}, stage 2: {} repeats, base {:g} um, move {:g} um; stage "
      "3: {} commands to {:g} um",
      o.daq, o.seed, o.config.empty() ? "built-in defaults" : o.config, go.matrix.repeats,
      go.matrix.base_um, go.matrix.move_um, go.polynomial.points, go.polynomial.max_um);
  calibration::GuidedSession session = open_session(o, session_file, plan_text, plan.size());

  // The controller the twin calibration starts from: the DAQ's rate, the paper's gains.
  control::SemiClosedLoopParams base;
  base.sample_time_s = config.twin.daq.sample_time_s;
  base.gains_sample_time_s = base.sample_time_s;
  const auto say = [](const std::string& text) {
    fmt::print(stderr, "{}", text);
    std::fflush(stderr);
  };
  const std::unique_ptr<calibration::InterferometerSource> source =
      make_source(o.interferometer, say);
  calibration::GuidedIo gio{*source, say, [&session_file](const calibration::GuidedSession& s) {
                              calibration::save_guided_session(session_file, s);
                            }};
  // Written before the stage moves: a folder that cannot take the session is found now.
  calibration::save_guided_session(session_file, session);
  GuidedRigs rigs(o, installation, base);

  const calibration::GuidedOutcome r =
      calibration::run_guided_calibration(rigs.stage2(), rigs.stage3(), base, session, gio, go);
  std::optional<runtime::LoopResult> loop_result;
  if (rigs.loop_rig())
    loop_result = rigs.loop_rig()->stop();  // the stage at rest at 0 V before anything is written
  if (!r.complete)
    throw core::InputError(fmt::format(
        "{} ended: {} of {} steps are recorded in {}; run the same command again to resume",
        source->name(), session.readings.size(), plan.size(), session_file));

  const FitDataFiles files = write_fit_data(o.out, r, session_file);  // before: see run_improved
  calibration::write_calibration_file(
      o.out, r.controller,
      fmt::format("piezoshift calibration, identified by the guided `piezoshift calibrate` on {} "
                  "with the interferometer from {}\nseed {}, configuration: {}, session: {}",
                  o.daq, o.interferometer, o.seed,
                  o.config.empty() ? "built-in defaults" : o.config, session_file));
  const rig::LoopRig* loop_rig = rigs.loop_rig();
  if (o.json) {
    nlohmann::json j = guided_json(o, r, files, session_file, plan.size());
    if (loop_rig) {
      const runtime::LoopStats& st = loop_rig->loop_stats();
      j["loop"] = {{"ticks", loop_result->ticks},
                   {"overruns", st.overruns},
                   {"max_consecutive_overruns", st.max_consecutive_overruns},
                   {"skipped_slots", st.skipped_slots},
                   {"host_samples_dropped", loop_result->host_samples_dropped}};
    }
    fmt::print("{}\n", j.dump(2));
    return 0;
  }
  print_fits(r.controller, r.matrix, r.polynomial);
  if (loop_rig)
    fmt::print("loop     {} ticks, {} overruns (at most {} in a row)\n", loop_result->ticks,
               loop_rig->loop_stats().overruns, loop_rig->loop_stats().max_consecutive_overruns);
  fmt::print("written: {}, {}, {} (session: {})\n", o.out, files.poses, files.points, session_file);
  return 0;
}

// The improved controller (docs/control.md): the paper's stages for A and p, then its own models.
int run_improved(const Options& o, const runtime::InstallationConfig& installation) {
  const config::ProjectConfig& config = installation.project;
  if (o.pid != "paper")
    throw core::InputError("--pid search: the improved controller has no PID to search");
  control::SemiClosedLoopParams base;
  base.sample_time_s = config.twin.daq.sample_time_s;
  // The improved calibration, then the travel's share of the start-up calibration's cost.
  const rig::ProcedureCost improved = calibration::improved_calibration_cost();
  check_procedure_cost("calibrate --controller improved", improved, config.twin,
                       o.max_physics_steps);
  work_begins();  // the twin's calibration
  calibration::ImprovedCalibrationOutcome ic;
  experiments::TravelRangeResult travel;
  {
    ProgressBar bar(3);
    calibration::ImprovedCalibrationOptions io;
    io.paper.limits = installation.safety;  // every stage's supervisor, as `run`'s
    ic = calibration::calibrate_improved(config, base, o.seed, io, bar.callback());
    experiments::TravelRangeOptions to = calibration::CalibrationOptions{}.travel;
    to.bench.limits = installation.safety;
    travel = experiments::run_travel_range(config, ic.controller, o.seed + 3, to);
  }
  if (!(travel.single_move_um > 0.0))
    throw rig::ProcedureFailed(
        fmt::format("calibration: the improved loop has no semi-closed-loop travel: {}",
                    travel.validity.reason));
  // The records stages 4 and 5 fitted, in the formats `fit improved` reads (docs/files.md),
  // each replaced atomically and before the calibration file: its presence implies them whole.
  const std::filesystem::path folder = std::filesystem::path(o.out).parent_path();
  if (!folder.empty())
    std::filesystem::create_directories(folder);
  const std::string excitation_file = (folder / "excitation.csv").string();
  const std::string mode_file = (folder / "mode_step.csv").string();
  write_improved_records(ic, excitation_file, mode_file);
  calibration::write_calibration_file(
      o.out, ic.controller,
      fmt::format("piezoshift calibration of the improved controller, identified on the digital "
                  "twin by `piezoshift calibrate --controller improved`\nseed {}, configuration: "
                  "{}",
                  o.seed, o.config.empty() ? "built-in defaults" : o.config),
      travel.single_move_um, travel.single_move_min_um);
  const ImprovedSummary summary{ic.controller.improved, ic.model,        ic.mode, ic.shaped,
                                &ic.large_move,         &ic.rate_verdict};
  if (o.json) {
    nlohmann::json j = improved_json(summary);
    j["calibration_file"] = o.out;
    j["controller"] = "improved";
    j["A"] = matrix_json(ic.controller.matrix.a);
    const auto& p = ic.controller.polynomial;
    j["p"] = {p.p3, p.p2, p.p1, p.p0};
    j["travel_z_max_um"] = travel.single_move_um;
    j["travel_semi_closed_um"] = travel.semi_closed_um;
    j["travel_z_min_um"] = travel.single_move_min_um;
    j["excitation_file"] = excitation_file;
    j["mode_file"] = mode_file;
    fmt::print("{}\n", j.dump(2));
    return 0;
  }
  print_fits(ic.controller, ic.static_map.matrix, ic.static_map.polynomial);
  print_improved(summary);
  fmt::print("travel   semi-closed loop {:.2f} um; one move reaches {:.2f} to {:.2f} um\n",
             travel.semi_closed_um, travel.single_move_min_um, travel.single_move_um);
  fmt::print("written: {}, {}, {}\n", o.out, excitation_file, mode_file);
  return 0;
}

// --interferometer fizeau: what it cannot do is refused before anything runs (check_request).
int run_fizeau(const Options& o) {
  return calibrate_from_fringes_command({.out = o.out,
                                         .config = o.config,
                                         .pid = o.pid,
                                         .controller = o.controller,
                                         .camera = o.camera,
                                         .surface = o.surface,
                                         .daq = o.daq,
                                         .free_run = o.free_run,
                                         .mask = o.mask,
                                         .seed = o.seed,
                                         .json = o.json,
                                         .max_physics_steps = o.max_physics_steps});
}

int run(const Options& o) {
  if (o.interferometer == "fizeau")
    return run_fizeau(o);
  if (!o.camera.empty() || !o.surface.empty() || !o.mask.empty())
    throw core::InputError(fmt::format(
        "{}: the Fizeau's camera, for --interferometer fizeau only",
        !o.camera.empty() ? "--camera" : (!o.surface.empty() ? "--surface" : "--mask")));
  if (!o.daq.empty()) {
    if (o.controller != "paper")
      throw core::InputError(
          "--controller improved: the guided calibration calibrates the paper's "
          "controller only");
    return run_guided(o);
  }
  if (!o.interferometer.empty())
    throw core::InputError(fmt::format(
        "--interferometer {} needs --daq (the guided calibration); only fizeau runs without it",
        o.interferometer));
  // [safety] too: every bench of the calibration is supervised as `run`'s loop is.
  const runtime::InstallationConfig installation =
      o.config.empty() ? runtime::InstallationConfig{}
                       : runtime::load_installation_config(o.config);
  const config::ProjectConfig& config = installation.project;
  if (o.controller == "improved")
    return run_improved(o, installation);
  calibration::CalibrationOptions co;
  co.limits = installation.safety;
  co.pid = o.pid == "paper" ? calibration::PidChoice::kPaper : calibration::PidChoice::kSearch;
  check_procedure_cost("calibrate",
                       calibration::calibration_cost(co, config.twin.daq.sample_time_s),
                       config.twin, o.max_physics_steps);
  work_begins();  // the twin's calibration
  calibration::CalibrationWithTravel ct;
  {
    ProgressBar bar(3);
    ct = calibration::calibrate_with_travel(config, o.seed, co, bar.callback());
  }
  const calibration::CalibrationOutcome& c = ct.calibration;
  const experiments::TravelRangeResult& travel = ct.travel;
  calibration::write_calibration_file(
      o.out, c.controller,
      fmt::format("piezoshift calibration, identified on the digital twin by `piezoshift "
                  "calibrate`\nseed {}, configuration: {}, PID gains: {}",
                  o.seed, o.config.empty() ? "built-in defaults" : o.config,
                  o.pid == "paper" ? "the paper's" : "searched"),
      travel.single_move_um, travel.single_move_min_um);
  const auto& g = c.controller.gains;
  if (o.json) {
    nlohmann::json j = paper_calibration_json(c.controller, c.matrix, c.polynomial);
    j["calibration_file"] = o.out;
    j["pid_worst_overshoot_pct"] =
        (o.pid == "paper" ? c.pid.paper : c.pid.best).worst.overshoot_pct;
    j["travel_z_max_um"] = travel.single_move_um;
    j["travel_semi_closed_um"] = travel.semi_closed_um;
    j["travel_z_min_um"] = travel.single_move_min_um;
    fmt::print("{}\n", j.dump(2));
    return 0;
  }
  fmt::print("stage 1  PID gains  kp {:g}, ki {:g}, kd {:g} ({} of {} candidates acceptable)\n",
             g.kp, g.ki, g.kd,
             std::count_if(c.pid.trials.begin(), c.pid.trials.end(),
                           [](const auto& t) { return t.acceptable; }),
             c.pid.trials.size());
  print_fits(c.controller, c.matrix, c.polynomial);
  fmt::print(
      "travel   semi-closed loop {:.2f} um (Section 4.1); one move reaches {:.2f} to "
      "{:.2f} um (written as z_min_um, z_max_um)\n",
      travel.semi_closed_um, travel.single_move_min_um, travel.single_move_um);
  fmt::print("written: {}\n", o.out);
  return 0;
}

}  // namespace

void add_calibrate_command(CLI::App& app, Action& action) {
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate", "The paper's three calibration stages on the twin; writes a calibration file");
  cmd->add_option("--out", o->out, "calibration file to write (TOML, replaced atomically)");
  add_physics_budget_option(cmd, o->max_physics_steps);
  cmd->add_option("--seed", o->seed, "seed of the twin's random numbers")
      ->check(whole_number(0, kAnyUnsigned));
  cmd->add_option("--config", o->config, "TOML configuration (configs/paper.toml's sections)");
  cmd->add_option(
         "--pid", o->pid,
         "paper: keep 0.6/0.2/0.001 (default); search: grid-search the gains on the full loop")
      ->check(CLI::IsMember({"paper", "search"}));
  cmd->add_option("--controller", o->controller,
                  "paper: the paper's PID, A and p (default); improved: A and p, then the "
                  "improved controller's models (docs/control.md)")
      ->check(CLI::IsMember({"paper", "improved"}));
  cmd->add_flag("--json", o->json, "print a JSON summary");
  cmd->add_option("--daq", o->daq,
                  "guided calibration on a bench: comedi:/dev/comediN (hardware, through the "
                  "real-time loop), sim (the twin, simulated clock) or sim-rt (the twin through "
                  "the real-time loop)");
  cmd->add_option("--interferometer", o->interferometer,
                  "guided: prompt (readings typed on stdin), file:PATH (the interferometer "
                  "software's CSV log, t_s,displacement_um) or sim (the twin's; not on comedi); "
                  "or fizeau: stages 2 and 3 from the Fizeau's fringes (on the twin's bench, or "
                  "with --daq sim-rt|comedi:/dev/comediN on the real-time loop)");
  cmd->add_option("--camera", o->camera,
                  "--interferometer fizeau: the camera whose fringes are read: twin, or "
                  "aravis:ID with --daq (docs/fizeau.md)");
  cmd->add_option("--mask", o->mask,
                  "--interferometer fizeau --daq: the pupil on the camera as a PNG (default: the "
                  "twin camera's, else found in the first scan's fringe modulation)");
  cmd->add_option("--surface", o->surface,
                  "--interferometer fizeau: the twin camera's test surface, as `psi simulate` "
                  "takes it (Z4=40,rough=0.5)");
  cmd->add_flag("--free-run", o->free_run,
                "--daq sim-rt (guided or fizeau): the loop runs as fast as the CPU allows, paced "
                "by the procedure (deterministic), instead of in real time");
  cmd->add_flag("--restart", o->restart,
                "guided: discard the session recorded beside --out instead of resuming it");
  cmd->add_option("--max-zero-drift-um", o->max_zero_drift_um,
                  "guided: largest change between repeated base readings at one point [um]");
  cmd->callback([o, &action] { action = [o] { return run(*o); }; });
}

}  // namespace piezoshift::app
