// `piezoshift analyze linearity|repeatability|step --data FILE.csv [--json] [--plot FIG.png]`:
// the performance metrics of the paper's Section 4 computed from recorded data (bench or twin).
//   linearity      columns zd_um,measured_um (one row per point of the sweep)
//   repeatability  column measured_um (one row per repeated move)
//   step           columns t_s,measured_um (one row per sample; in a file with a state column,
//                  a `run` log, the rows before the first with state != 0: the controlled part)
// The column vocabulary is docs/files.md's; --column NAME reads the measured values from another
// column (interferometer1_um of a `run` or `simulate` log). Column order is free and other
// columns are ignored. Bad data exits with status 2 and a message
// naming the file and, where one applies, the line and column. --plot draws the matching figure
// with gnuplot (PNG, or SVG for a .svg name) and keeps its .gp script and .dat data beside it.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/experiments/metrics_figures.hpp"
#include "piezoshift/experiments/metrics_linearity.hpp"
#include "piezoshift/experiments/metrics_repeatability.hpp"
#include "piezoshift/experiments/metrics_step_response.hpp"
#include "piezoshift/io/csv_table.hpp"
#include "piezoshift/io/plot.hpp"
#include "whole_number.hpp"

namespace piezoshift::app {
namespace {

using Json = nlohmann::ordered_json;

struct AnalyzeOptions {
  std::string data_path;
  bool json = false;
  std::string plot_path;  // empty: no figure
  std::string column = "measured_um";
  experiments::StepResponseOptions step;
  std::int64_t median_window = 5;
};

// Runs a metric; a MetricsError (which does not know the file) gets the file name in front.
template <class F>
auto with_file(const std::string& path, F&& metric) {
  try {
    return metric();
  } catch (const experiments::MetricsError& e) {
    throw core::InputError(fmt::format("{}: {}", path, e.what()));
  }
}

// Draws the figure if asked; a drawing failure is reported but the metrics already printed
// stand, so the status is 1 (not bad input).
int draw(const AnalyzeOptions& o, const io::Figure& figure) {
  if (o.plot_path.empty())
    return 0;
  work_begins();  // gnuplot and the files
  io::Figure f = figure;
  const bool svg = o.plot_path.size() > 4 && o.plot_path.ends_with(".svg");
  f.png = !svg;
  f.svg = svg;
  try {
    const io::PlotFiles files = io::render(f, o.plot_path);
    if (!o.json)
      fmt::print("figure: {} (script {})\n", (svg ? *files.svg : *files.png).string(),
                 files.script.string());
    return 0;
  } catch (const io::PlotError& e) {
    fmt::print(stderr, "piezoshift: error: {}\n", e.what());
    return 1;
  }
}

Json number_or_null(double v) {
  return std::isfinite(v) ? Json(v) : Json(nullptr);
}

int run_linearity(const AnalyzeOptions& o) {
  const io::CsvTable t = io::CsvTable::load(o.data_path);
  t.require_columns({"zd_um", o.column});
  const std::vector<double> x = t.column("zd_um");
  const std::vector<double> y = t.column(o.column);
  const experiments::LinearityMetrics m =
      with_file(o.data_path, [&] { return experiments::linearity_metrics(x, y); });
  if (o.json) {
    const Json out{{"data", o.data_path},
                   {"n", m.n},
                   {"linearity_zero_end_pct", m.linearity_zero_end_pct},
                   {"linearity_best_fit_pct", m.linearity_best_fit_pct},
                   {"span_um", m.span_um},
                   {"max_deviation_zero_end_um", m.max_deviation_zero_end_um},
                   {"max_deviation_best_fit_um", m.max_deviation_best_fit_um},
                   {"zero_end_slope", m.zero_end_slope},
                   {"zero_end_intercept_um", m.zero_end_intercept_um},
                   {"best_fit_slope", m.best_fit_slope},
                   {"best_fit_intercept_um", m.best_fit_intercept_um}};
    fmt::print("{}\n", out.dump(2));
  } else {
    fmt::print("Linearity of {} points in {} (base: measured span {:.4f} um)\n", m.n, o.data_path,
               m.span_um);
    fmt::print("zero-end point   {:.4f} %  (max deviation {:.2f} nm)\n", m.linearity_zero_end_pct,
               1000.0 * m.max_deviation_zero_end_um);
    fmt::print("best-fit line    {:.4f} %  (max deviation {:.2f} nm; y = {:.6f} + {:.6f} x)\n",
               m.linearity_best_fit_pct, 1000.0 * m.max_deviation_best_fit_um,
               m.best_fit_intercept_um, m.best_fit_slope);
  }
  return draw(o, experiments::linearity_figure(x, y, m, "Linearity: " + o.data_path));
}

int run_repeatability(const AnalyzeOptions& o) {
  const io::CsvTable t = io::CsvTable::load(o.data_path);
  t.require_columns({o.column});
  const std::vector<double> z = t.column(o.column);
  const experiments::RepeatabilityMetrics r =
      with_file(o.data_path, [&] { return experiments::repeatability_metrics(z); });
  if (o.json) {
    const Json out{
        {"data", o.data_path},  {"n", r.n},           {"repeatability_nm", r.repeatability_nm},
        {"mean_um", r.mean_um}, {"min_um", r.min_um}, {"max_um", r.max_um}};
    fmt::print("{}\n", out.dump(2));
  } else {
    fmt::print("Repeatability (Eq. 9) of {} values in {}\n", r.n, o.data_path);
    fmt::print("e_R  {:.3f} nm   mean {:.6f} um   range [{:.6f}, {:.6f}] um\n", r.repeatability_nm,
               r.mean_um, r.min_um, r.max_um);
  }
  const experiments::RepeatabilitySet set{o.data_path, z};
  return draw(o, experiments::repeatability_figure(std::span(&set, 1)));
}

int run_step(const AnalyzeOptions& o_in) {
  AnalyzeOptions o = o_in;
  if (o.median_window % 2 == 0)  // the option's check has its range
    throw core::InputError(fmt::format("--median-window {}: must be odd", o.median_window));
  if (!std::isfinite(o.step.step_time_s))
    throw core::InputError(
        fmt::format("--step-time-s {}: must be a finite number", o.step.step_time_s));
  o.step.median_window = static_cast<std::size_t>(o.median_window);
  const io::CsvTable t = io::CsvTable::load(o.data_path);
  t.require_columns({"t_s", o.column});
  std::vector<double> ts = t.column("t_s");
  std::vector<double> y = t.column(o.column);
  // A `run` log goes on through the ramp to 0 V after its controlled part (state 1, stopping)
  // or a fault: the step is the part where the supervisor was running (state 0).
  if (t.has_column("state")) {
    const std::vector<double> state = t.column("state");
    const auto end = static_cast<std::size_t>(
        std::find_if(state.begin(), state.end(), [](double v) { return v != 0.0; }) -
        state.begin());
    ts.resize(end);
    y.resize(end);
  }
  const experiments::StepResponseMetrics m =
      with_file(o.data_path, [&] { return experiments::step_response_metrics(ts, y, o.step); });
  if (o.json) {
    const Json out{{"data", o.data_path},
                   {"n", ts.size()},
                   {"step_time_s", o.step.step_time_s},
                   {"initial_um", m.initial_um},
                   {"final_um", m.final_um},
                   {"step_um", m.step_um},
                   {"rise_time_s", number_or_null(m.rise_time_s)},
                   {"overshoot_pct", m.overshoot_pct},
                   {"peak_um", m.peak_um},
                   {"peak_time_s", m.peak_time_s},
                   {"band_pct", m.band_pct},
                   {"settling_time_pct_s", number_or_null(m.settling_time_pct_s)},
                   {"band_nm", m.band_nm},
                   {"settling_time_abs_s", number_or_null(m.settling_time_abs_s)},
                   {"median_window", o.step.median_window}};
    fmt::print("{}\n", out.dump(2));
  } else {
    auto time = [](double v) {
      return std::isfinite(v) ? fmt::format("{:.4f} s", v) : std::string("not reached");
    };
    fmt::print("Step response in {}: {:.4f} um -> {:.4f} um (step {:.4f} um at {} s)\n",
               o.data_path, m.initial_um, m.final_um, m.step_um, o.step.step_time_s);
    fmt::print("rise time (10-90 %)      {}\n", time(m.rise_time_s));
    fmt::print("overshoot                {:.3f} % of the step\n", m.overshoot_pct);
    fmt::print("settling time +-{:g} %     {}\n", m.band_pct, time(m.settling_time_pct_s));
    fmt::print("settling time +-{:g} nm    {}\n", m.band_nm, time(m.settling_time_abs_s));
  }
  return draw(o,
              experiments::step_response_figure(ts, y, m, o.step, "Step response: " + o.data_path));
}

}  // namespace

void add_analyze_command(CLI::App& app, Action& action) {
  CLI::App* analyze = app.add_subcommand(
      "analyze", "Performance metrics (linearity, repeatability, step) from recorded data");
  analyze->require_subcommand(1);
  auto o = std::make_shared<AnalyzeOptions>();

  CLI::App* lin = analyze->add_subcommand(
      "linearity", "Zero-end and best-fit linearity (columns zd_um, measured_um)");
  CLI::App* rep =
      analyze->add_subcommand("repeatability", "Eq. 9 repeatability (column measured_um)");
  CLI::App* step = analyze->add_subcommand(
      "step", "Rise time, overshoot, settling times (columns t_s, measured_um)");
  for (CLI::App* sub : {lin, rep, step}) {
    sub->add_option("--data", o->data_path, "CSV file with a header row")->required();
    sub->add_flag("--json", o->json, "Machine-readable output");
    sub->add_option("--plot", o->plot_path,
                    "Draw the figure with gnuplot to this .png (or .svg) file");
    sub->add_option("--column", o->column,
                    "Column of the measured values (e.g. interferometer1_um of a run or simulate "
                    "log; docs/files.md)")
        ->capture_default_str();
  }
  step->add_option("--step-time-s", o->step.step_time_s, "When the step was commanded [s]")
      ->capture_default_str();
  step->add_option("--band-pct", o->step.band_pct, "Relative settling band [+- % of the step]")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  step->add_option("--band-nm", o->step.band_nm, "Absolute settling band [+- nm]")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  step->add_option("--median-window", o->median_window,
                   "Running-median length against spikes [samples, odd; 1: off]")
      ->capture_default_str()
      ->check(whole_number(1, experiments::kMaxMedianWindow));

  // A --plot that cannot be drawn (a folder, a folder that takes no file) is refused
  // before the data is read, not after the metrics are printed.
  const auto checked = [o](int (*run)(const AnalyzeOptions&)) {
    return [o, run] {
      if (!o->plot_path.empty())
        io::check_output_path(o->plot_path, "--plot");
      return run(*o);
    };
  };
  lin->callback([&action, checked] { action = checked(run_linearity); });
  rep->callback([&action, checked] { action = checked(run_repeatability); });
  step->callback([&action, checked] { action = checked(run_step); });
}

}  // namespace piezoshift::app
