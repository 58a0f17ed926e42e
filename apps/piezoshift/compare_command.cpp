// `piezoshift compare`: the paper's controller, the improved one and the oracle, side by side
// (docs/compare.md).
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "command.hpp"
#include "physics_budget.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/reproduction/comparison.hpp"
#include "piezoshift/reproduction/comparison_report.hpp"
#include "piezoshift/reproduction/figure_format.hpp"
#include "piezoshift/reproduction/reproduction_cost.hpp"
#include "piezoshift/reproduction/text_table.hpp"
#include "piezoshift/runtime/safety_ranges.hpp"
#include "progress_bar.hpp"

namespace piezoshift::app {
namespace {

// Each seed is a full calibration and experiment set per controller (about 10 s with the
// paper's schedule), so a list this long is already a night's run.
constexpr std::size_t kMaxSeeds = 100;

// "1-8", "3", "1,4,9" or "1-3,7": whole numbers, ranges low to high, no seed twice.
std::optional<std::vector<std::uint64_t>> parse_seeds(const std::string& text) {
  std::vector<std::uint64_t> out;
  const auto number = [](std::string_view s, std::uint64_t& v) {
    const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
    return !s.empty() && r.ec == std::errc() && r.ptr == s.data() + s.size();
  };
  std::string_view rest = text;
  while (true) {
    const std::size_t comma = rest.find(',');
    const std::string_view item = rest.substr(0, comma);
    const std::size_t dash = item.find('-');
    std::uint64_t lo = 0, hi = 0;
    if (dash == std::string_view::npos) {
      if (!number(item, lo))
        return std::nullopt;
      hi = lo;
    } else if (!number(item.substr(0, dash), lo) || !number(item.substr(dash + 1), hi) || hi < lo) {
      return std::nullopt;
    }
    if (hi - lo >= kMaxSeeds)
      return std::nullopt;
    for (std::uint64_t s = lo; s <= hi; ++s) {
      if (std::find(out.begin(), out.end(), s) != out.end() || out.size() >= kMaxSeeds)
        return std::nullopt;
      out.push_back(s);
      if (s == hi)  // hi may be the largest uint64
        break;
    }
    if (comma == std::string_view::npos)
      break;
    rest.remove_prefix(comma + 1);
  }
  return out;
}

// A median as the terminal shows it, formatted as the report does: never a number when it is
// not valid (the reasons follow on stderr) or not applicable (its reason under the tables).
std::string cell(const reproduction::FigureValue& m, const std::string& unit, double resolution) {
  if (!m.measured)
    return "-";
  if (!m.validity.valid)
    return "NOT VALID";
  if (!m.not_applicable.empty())
    return "n/a";
  return reproduction::format_figure(m.value, unit, resolution);
}

// The medians and the targets as two aligned tables.
std::string summary_tables(const reproduction::ComparisonResult& result) {
  std::vector<std::string> header{"median over seeds"};
  for (const reproduction::LoopVariant k : result.variants())
    header.push_back(reproduction::variant_key(k));
  std::vector<std::vector<std::string>> medians{std::move(header)};
  for (std::size_t i = 0; i < result.figures.size(); ++i) {
    const auto& f = result.figures[i];
    std::vector<std::string> row{f.label};
    for (const reproduction::LoopVariant k : result.variants())
      row.push_back(cell(result.medians[i][static_cast<std::size_t>(k)], f.unit, f.resolution));
    medians.push_back(std::move(row));
  }
  std::vector<std::vector<std::string>> targets{
      {"target (improved controller's median)", "bound", "median", "met"}};
  std::string not_judged;
  for (const std::string& why : result.not_applicable_reasons())
    not_judged += fmt::format("  n/a: {}\n", why);
  for (const auto& t : result.targets) {
    targets.push_back({t.text, t.bound_text, cell(t.improved, t.unit, t.resolution), t.verdict()});
    if (!t.not_applicable.empty())
      not_judged += fmt::format("  n/a: {}: {}\n", t.text, t.not_applicable);
  }
  if (!result.rate_verdict.empty())
    not_judged += "  " + reproduction::rate_verdict_text(result) + "\n";
  std::string out =
      reproduction::text_table(medians) + "\n" + reproduction::text_table(targets) + not_judged;
  if (result.options.fringes) {
    std::vector<std::vector<std::string>> spread{
        {"Table 4, fringes vs XL-80", "paper_fringes median", "paper's seed spread", "within"}};
    for (const auto& c : result.fringes_within_spread)
      spread.push_back(reproduction::spread_row(result, c));
    out += "\n" + reproduction::text_table(spread);
  }
  if (result.options.lock)
    out += fmt::format("\n{}\n{}{}\n", reproduction::hold_title(result),
                       reproduction::text_table(reproduction::hold_median_table(result)),
                       reproduction::hold_check_text(result));
  return out;
}

struct Options {
  std::string config;
  std::string seeds = "1-8";
  std::string out;
  bool quick = false;
  bool json = false;
  bool fringes = false;
  bool lock = false;
  double lock_hold_s = reproduction::kDefaultHold_s;
  double max_physics_steps = plant::kDefaultPhysicsStepBudget;  // per seed
};

int run(const Options& o) {
  const config::ProjectConfig config = o.config.empty()
                                           ? config::ProjectConfig{}
                                           : runtime::load_installation_config(o.config).project;
  reproduction::CompareOptions co;
  co.seeds = *parse_seeds(o.seeds);  // checked by the option's validator
  co.quick = o.quick;
  co.fringes = o.fringes;
  co.lock = o.lock;
  co.lock_hold_s = o.lock_hold_s;
  // Per seed: the seeds run one after another, each a whole comparison of its own.
  check_procedure_cost("compare, one seed", reproduction::compare_seed_cost(co), config.twin,
                       o.max_physics_steps);
  work_begins();  // every seed's calibrations and experiments
  reproduction::ComparisonResult result;
  {
    // The bar counts changes of label. Per seed: two calibrations (3 labels each), three
    // experiment sets of 7 labels (the grid and downward linearity share one), and at 10 kHz the
    // improved controller's calibration (3) and phase step (1). Counted on `compare --quick
    // --seeds 1`: the bar ran [1/31] to [30/31] (the improved controller's 10 kHz calibration
    // showed 2 labels). --fringes adds the calibration from fringes (3 labels) and its
    // experiment set (7; its 10 kHz step shares the set's last label, as the paper's does):
    // [1/41] to [40/41] on `compare --quick --fringes --seeds 1`. --lock adds one label a hold.
    const int per_seed = 2 * 3 + 3 * 7 + 3 + 1 + (co.fringes ? 3 + 7 : 0) +
                         (co.lock ? static_cast<int>(reproduction::kHoldVariants.size()) : 0);
    ProgressBar bar(static_cast<int>(co.seeds.size()) * per_seed);
    result = reproduction::compare(config, co, bar.callback());
  }
  const int status = result.valid() ? 0 : rig::kExitNotValid;
  std::string report;
  if (!o.out.empty()) {
    const std::string label =
        o.config.empty() ? "built-in defaults (configs/paper.toml)" : o.config;
    const reproduction::ReportFiles files =
        reproduction::write_comparison_report(result, o.out, label);
    report = fmt::format("report: {}\n        {}\n", files.markdown.string(), files.html.string());
  }
  if (o.json) {
    fmt::print("{}\n", reproduction::comparison_json(result).dump(2));
  } else {
    fmt::print("piezoshift compare: {} seed(s), {:.0f} s simulated in {:.1f} s\n", co.seeds.size(),
               result.simulated_time_s, result.wall_time_s);
    fmt::print("{}", summary_tables(result));
    fmt::print("{}", report);
  }
  if (status != 0) {
    fmt::print(stderr, "piezoshift: compare: not valid (exit status 4):\n");
    for (const std::string& why : result.invalid_reasons())
      fmt::print(stderr, "  {}\n", why);
  }
  return status;
}

}  // namespace

void add_compare_command(CLI::App& app, Action& action) {
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "compare",
      "The paper's controller, the improved one and the oracle through the same experiments");
  cmd->add_option("--config", o->config, "TOML configuration (configs/paper.toml's sections)");
  cmd->add_option("--seeds", o->seeds, "seeds of the twin: A-B, a comma list, or both (1-3,7)")
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            return parse_seeds(text)
                       ? std::string()
                       : fmt::format(
                             "{} is not a list of distinct seeds (e.g. 1-8 or 1,3,5; at "
                             "most {})",
                             text, kMaxSeeds);
          },
          "SEEDS"));
  add_physics_budget_option(cmd, o->max_physics_steps);
  cmd->add_flag("--quick", o->quick, "shortened schedule (tests, a first look)");
  cmd->add_flag("--json", o->json, "print the JSON summary");
  cmd->add_flag("--fringes", o->fringes,
                "a fourth column: the paper's controller calibrated from the Fizeau's fringes, no "
                "XL-80; costs its calibration (10 to 16 s of wall time a seed) and its "
                "experiments (about as long as the paper's column)");
  CLI::Option* lock = cmd->add_flag(
      "--lock", o->lock,
      "the Fizeau hold: per seed the paper's and the improved controller, "
      "each unlocked and locked, as `measure --free-run --averages 10 --hold-s H "
      "[--lock]` on a 96 px twin camera with the cavity's drift in the fringes; a "
      "table of its own, not a column; costs four holds a seed (5 to 8 s of wall time "
      "each for 60 s)");
  cmd->add_option("--lock-hold-s", o->lock_hold_s,
                  "with --lock: the hold's length in loop time (s, in (0, 3600])")
      ->capture_default_str()
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            double v = 0.0;
            const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
            const bool ok =
                r.ec == std::errc() && r.ptr == text.data() + text.size() && v > 0.0 && v <= 3600.0;
            return ok ? std::string() : fmt::format("{} is not a hold length in (0, 3600] s", text);
          },
          "SECONDS"))
      ->needs(lock);
  cmd->add_option("--out", o->out,
                  "output folder for comparison.md, comparison.html, figures, CSVs");
  cmd->callback([o, &action] { action = [o] { return run(*o); }; });
}

}  // namespace piezoshift::app
