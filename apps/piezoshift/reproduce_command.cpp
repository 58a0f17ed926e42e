// `piezoshift reproduce`: calibrate the twin, run the paper's four experiments, write the report.
#include <unistd.h>

#include <cstdio>
#include <memory>
#include <string>

#include <fmt/core.h>

#include "command.hpp"
#include "physics_budget.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/reproduction/report.hpp"
#include "piezoshift/reproduction/reproduction.hpp"
#include "piezoshift/reproduction/reproduction_cost.hpp"
#include "piezoshift/reproduction/summary.hpp"
#include "piezoshift/runtime/safety_ranges.hpp"
#include "progress_bar.hpp"
#include "whole_number.hpp"

namespace piezoshift::app {
namespace {

struct Options {
  std::string out = "out/reproduce";
  std::uint64_t seed = 1;
  std::string config;
  std::string pid = "paper";
  bool quick = false;
  bool json = false;
  double max_physics_steps = plant::kDefaultPhysicsStepBudget;
};

int run(const Options& o) {
  const config::ProjectConfig config = o.config.empty()
                                           ? config::ProjectConfig{}
                                           : runtime::load_installation_config(o.config).project;
  check_procedure_cost("reproduce", reproduction::reproduce_cost(o.quick), config.twin,
                       o.max_physics_steps);
  reproduction::ReproduceOptions ro;
  ro.seed = o.seed;
  ro.quick = o.quick;
  ro.pid = o.pid == "search" ? calibration::PidChoice::kSearch : calibration::PidChoice::kPaper;
  reproduction::ReproductionResult result;
  {
    // The bar counts changes of label: PID gains, matrix A, polynomial p; for the paper's
    // controller travel range, step, linearity, repeatability at 5 and 10 um, linearity (the
    // 0.25 um grid and downwards: one label), phase step; the oracle's linearity with the
    // paper's controller; the oracle's seven.
    ProgressBar bar(3 + 7 + 1 + 7);
    result = reproduction::reproduce(config, ro, bar.callback());
  }
  const std::string label = o.config.empty() ? "built-in defaults (configs/paper.toml)" : o.config;
  const reproduction::ReportFiles files = reproduction::write_report(result, o.out, label);
  const int status = result.valid() ? 0 : reproduction::kExitInvalidExperiment;
  if (o.json) {
    fmt::print("{}\n", reproduction::summary_json(result).dump(2));
    return status;
  }
  const auto& t = result;
  fmt::print("piezoshift reproduce: {:.0f} s simulated in {:.2f} s\n", t.simulated_time_s,
             t.wall_time_s);
  // A row that is not valid shows why, never a number.
  const auto row = [](const char* name, const rig::Validity& v, const std::string& value,
                      const char* paper) {
    if (v.valid)
      fmt::print("  {:<16} {:<46} (paper: {})\n", name, value, paper);
    else
      fmt::print("  {:<16} NOT VALID: {}\n", name, v.reason);
  };
  row("travel range", t.travel.validity,
      fmt::format("{:.2f} um open loop, {:.1f} um semi-closed loop", t.travel.open_loop_um,
                  t.travel.semi_closed_um),
      "12.9, 11.5");
  row("step response", t.step.validity,
      fmt::format("settles (+-2 %) in {:.3f} s at {:g} um", t.step.metrics.settling_time_pct_s,
                  t.step.desired_um.back()),
      "< 0.3 s");
  row("linearity", t.linearity.validity,
      fmt::format("{:.3f} % zero-end, {:.3f} % best fit",
                  t.linearity.metrics.linearity_zero_end_pct,
                  t.linearity.metrics.linearity_best_fit_pct),
      "0.21 %");
  rig::Validity repeat = t.repeat_5um.validity;
  if (!t.repeat_10um.validity.valid)
    repeat.fail(t.repeat_10um.validity.reason);
  row("repeatability", repeat,
      fmt::format("{:.2f} nm at 5 um, {:.2f} nm at 10 um", t.repeat_5um.metrics.repeatability_nm,
                  t.repeat_10um.metrics.repeatability_nm),
      "2, 3 nm");
  rig::Validity oracle;
  if (!t.oracle.table4_valid())
    oracle.fail(t.oracle.invalid_reasons().front());
  row("oracle", oracle,
      fmt::format("{:.3f} %, {:.2f} / {:.2f} nm (plate feedback: impossible on hardware)",
                  t.oracle.linearity.metrics.linearity_zero_end_pct,
                  t.oracle.repeat_5um.metrics.repeatability_nm,
                  t.oracle.repeat_10um.metrics.repeatability_nm),
      "-");
  const reproduction::PhaseMeasurement& m = t.measurement;
  row("measurement", m.validity,
      fmt::format("{} on the twin camera: {:.2f} nm RMS, {:.3f} nm from the truth (floor "
                  "{:.3f}), steps within {:.1f} mrad",
                  m.algorithm, m.analysis.figures.rms, m.error_rms_nm, m.ideal_error_rms_nm,
                  m.analysis.step_error_max_mrad),
      "-");
  fmt::print("report: {}\n        {}\n", files.markdown.string(), files.html.string());
  if (status != 0) {
    fmt::print(stderr, "piezoshift: reproduce: not valid (exit status 4):\n");
    for (const std::string& why : result.invalid_reasons())
      fmt::print(stderr, "  {}\n", why);
  }
  return status;
}

}  // namespace

void add_reproduce_command(CLI::App& app, Action& action) {
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "reproduce", "Calibrate the twin, run the paper's four experiments, write the report");
  cmd->add_option("--out", o->out, "output folder for report.md, report.html, figures, CSVs");
  cmd->add_option("--seed", o->seed, "seed of the twin's random numbers")
      ->check(whole_number(0, kAnyUnsigned));
  cmd->add_option("--config", o->config, "TOML configuration (configs/paper.toml's sections)");
  cmd->add_option("--pid", o->pid, "paper: the paper's gains; search: the stage-1 search's")
      ->check(CLI::IsMember({"paper", "search"}));
  add_physics_budget_option(cmd, o->max_physics_steps);
  cmd->add_flag("--quick", o->quick, "shortened schedule (tests, a first look)");
  cmd->add_flag("--json", o->json, "print the JSON summary");
  cmd->callback([o, &action] { action = [o] { return run(*o); }; });
}

}  // namespace piezoshift::app
