// `piezoshift reproduce`: calibrate the twin, run the paper's four experiments, write the report.
#include <unistd.h>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "command.hpp"
#include "physics_budget.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/reproduction/figure_format.hpp"
#include "piezoshift/reproduction/paper_bands.hpp"
#include "piezoshift/reproduction/report.hpp"
#include "piezoshift/reproduction/reproduction.hpp"
#include "piezoshift/reproduction/reproduction_cost.hpp"
#include "piezoshift/reproduction/summary.hpp"
#include "piezoshift/reproduction/text_table.hpp"
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
  // [safety] too: every bench is supervised as `run`'s loop is.
  const runtime::InstallationConfig installation =
      o.config.empty() ? runtime::InstallationConfig{}
                       : runtime::load_installation_config(o.config);
  const config::ProjectConfig& config = installation.project;
  check_procedure_cost("reproduce", reproduction::reproduce_cost(o.quick), config.twin,
                       o.max_physics_steps);
  work_begins();  // the calibration, the experiments, the report
  reproduction::ReproduceOptions ro;
  ro.seed = o.seed;
  ro.quick = o.quick;
  ro.limits = installation.safety;
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
  // Table 4 against the paper's bands (the report's table); a row that is not valid shows no
  // number (the reasons follow on stderr).
  std::vector<std::vector<std::string>> rows{
      {"Table 4", "twin (this run)", "the paper", "band", "against the band"}};
  for (const reproduction::PaperBandRow& b : reproduction::paper_band_rows(t))
    rows.push_back({b.figure, b.valid ? b.twin : "NOT VALID", b.paper, b.band, b.verdict()});
  fmt::print("{}", reproduction::text_table(rows));
  const auto& ol = t.oracle.linearity.metrics;
  if (t.oracle.table4_valid()) {
    fmt::print(
        "  oracle (plate feedback: impossible on hardware): linearity {}{}, repeatability {} at "
        "5 µm, {} at 10 µm\n",
        reproduction::format_figure(ol.linearity_zero_end_pct, "%"),
        ol.linearity_zero_end_pct == 0.0 ? " (exact by construction)" : "",
        reproduction::format_figure(t.oracle.repeat_5um.metrics.repeatability_nm, "nm"),
        reproduction::format_figure(t.oracle.repeat_10um.metrics.repeatability_nm, "nm"));
  } else {
    fmt::print("  oracle: NOT VALID: {}\n", t.oracle.invalid_reasons().front());
  }
  const reproduction::PhaseMeasurement& m = t.measurement;
  if (m.validity.valid) {
    fmt::print(
        "  measurement: {} on the twin camera: {} RMS, {} from the truth (floor {}), steps "
        "within {:.1f} mrad\n",
        m.algorithm, reproduction::format_figure(m.analysis.figures.rms, "nm"),
        reproduction::format_figure(m.error_rms_nm, "nm"),
        reproduction::format_figure(m.ideal_error_rms_nm, "nm"), m.analysis.step_error_max_mrad);
  } else {
    fmt::print("  measurement: NOT VALID: {}\n", m.validity.reason);
  }
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
