// `piezoshift calibrate`: the paper's three calibration stages on the twin, written as a
// calibration file that `piezoshift run --calibration` loads.
#include <algorithm>
#include <memory>
#include <string>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "piezoshift/calibration/calibration_file.hpp"
#include "piezoshift/calibration/calibration_procedure.hpp"
#include "piezoshift/experiments/paper_experiments.hpp"
#include "piezoshift/io/project_config.hpp"
#include "piezoshift/runtime/safety_ranges.hpp"
#include "progress_bar.hpp"
#include "whole_number.hpp"

namespace piezoshift::app {
namespace {

struct Options {
  std::string out = "calibration.toml";
  std::uint64_t seed = 1;
  std::string config;
  std::string pid = "paper";
  bool json = false;
};

nlohmann::json matrix_json(const control::Mat3& a) {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& row : a)
    rows.push_back({row[0], row[1], row[2]});
  return rows;
}

int run(const Options& o) {
  const io::ProjectConfig config =
      o.config.empty() ? io::ProjectConfig{} : runtime::load_installation_config(o.config).project;
  calibration::CalibrationOptions co;
  co.pid = o.pid == "paper" ? calibration::PidChoice::kPaper : calibration::PidChoice::kSearch;
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
  const auto& p = c.controller.polynomial;
  if (o.json) {
    nlohmann::json j;
    j["calibration_file"] = o.out;
    j["pid_gains"] = {{"kp", g.kp}, {"ki", g.ki}, {"kd", g.kd}};
    j["pid_worst_overshoot_pct"] =
        (o.pid == "paper" ? c.pid.paper : c.pid.best).worst.overshoot_pct;
    j["A"] = matrix_json(c.controller.matrix.a);
    j["p"] = {p.p3, p.p2, p.p1, p.p0};
    j["A_rms_residual_um"] = c.matrix.fit.rms_residual_um;
    j["condition_number"] = c.matrix.fit.condition_number;
    j["p_rms_residual_um"] = c.polynomial.fit.rms_residual_um;
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
  fmt::print("stage 2  matrix A   rms residual {:.4f} um, cond(A) {:.3f}\n",
             c.matrix.fit.rms_residual_um, c.matrix.fit.condition_number);
  for (const auto& row : c.controller.matrix.a) {
    fmt::print("           [{:8.4f} {:8.4f} {:8.4f}]\n", row[0], row[1], row[2]);
  }
  fmt::print("stage 3  cubic p    p3 {:.4e}, p2 {:.4e}, p1 {:.5f}, p0 {:.4f} um (rms {:.4f} um)\n",
             p.p3, p.p2, p.p1, p.p0, c.polynomial.fit.rms_residual_um);
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
  cmd->add_option("--seed", o->seed, "seed of the twin's random numbers")
      ->check(whole_number(0, kAnyUnsigned));
  cmd->add_option("--config", o->config, "TOML configuration (configs/paper.toml's sections)");
  cmd->add_option(
         "--pid", o->pid,
         "paper: keep 0.6/0.2/0.001 (default); search: grid-search the gains on the full loop")
      ->check(CLI::IsMember({"paper", "search"}));
  cmd->add_flag("--json", o->json, "print a JSON summary");
  cmd->callback([o, &action] { action = [o] { return run(*o); }; });
}

}  // namespace piezoshift::app
