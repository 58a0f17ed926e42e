#include "piezoshift/reproduction/comparison.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <utility>

#include <fmt/core.h>

#include "piezoshift/core/wall_time.hpp"
#include "piezoshift/reproduction/figure_format.hpp"

#include "comparison_seed.hpp"

namespace piezoshift::reproduction {
namespace {

using rig::Validity;

FigureValue figure(double value, const Validity& v) {
  FigureValue f;
  f.validity = v;
  if (v.valid)
    f.value = value;
  return f;
}

FigureValue not_measured() {
  FigureValue f;
  f.measured = false;
  return f;
}

FigureValue not_applicable(const std::string& why) {
  FigureValue f;
  f.not_applicable = why;
  return f;
}

// A figure of an experiment of the set; a failed calibration makes every figure not valid.
template <class Get>
std::function<FigureValue(const VariantRun&)> from_set(Get get) {
  return [get](const VariantRun& r) {
    if (!r.calibration.valid)
      return figure(0.0, r.calibration);
    return get(r.set);
  };
}

// A figure of the phase step at 10 kHz; not measured where it was not run (the oracle).
std::function<FigureValue(const VariantRun&)> at_10kHz(
    double experiments::PhaseStepResult::*member) {
  return [member](const VariantRun& r) {
    if (!r.calibration.valid)
      return figure(0.0, r.calibration);
    if (!r.ran_10kHz)
      return not_measured();
    if (!r.not_applicable_10kHz.empty())
      return not_applicable(r.not_applicable_10kHz);
    return figure(r.phase_step_10kHz.*member, r.phase_step_10kHz.validity);
  };
}

// The worst channel's margin at the i-th loop rate; the oracle has no analysis of its own.
std::function<FigureValue(const VariantRun&)> margin(std::size_t i, bool gain) {
  return [i, gain](const VariantRun& r) {
    if (!r.calibration.valid)
      return figure(0.0, r.calibration);
    FigureValue f;
    if (i >= r.inner_loop.size()) {
      f.measured = false;
      return f;
    }
    const InnerLoopAnalysis& a = r.inner_loop[i];
    if (a.sample_time_s == kFastSampleTime_s && !r.not_applicable_10kHz.empty())
      return not_applicable(r.not_applicable_10kHz);
    if (!a.validity.valid)
      return figure(0.0, a.validity);
    const runtime::StabilityMargins w = a.worst();
    return figure(gain ? w.gain_margin_dB : w.phase_margin_deg, a.validity);
  };
}

Target target(std::string text, std::string key, double bound, bool at_least,
              std::string bound_text) {
  Target t;
  t.text = std::move(text);
  t.key = std::move(key);
  t.bound = bound;
  t.at_least = at_least;
  t.bound_text = std::move(bound_text);
  return t;
}

// Linearity against the oracle is judged on the unseen grid and downwards, not on the
// paper's whole-micron levels, where the oracle reads exactly 0 and 1.2 x 0 asks for exactly 0.
constexpr const char* kOracleExactOnThePapersLevels =
    "the oracle reads exactly 0 on the paper's whole-micron levels (its plate held on the levels "
    "the interferometer reads to 1 nm), so 1.2 × 0 would ask for exactly 0; judged on the 0.25 µm "
    "grid and downwards instead";

}  // namespace

const char* Target::verdict() const noexcept {
  if (!not_applicable.empty())
    return "n/a";
  if (!improved.measured)
    return "-";
  return met ? "yes" : "no";
}

std::vector<LoopVariant> loop_variants(const CompareOptions& options) {
  std::vector<LoopVariant> v(kLoopVariants.begin(), kLoopVariants.end());
  if (options.fringes)
    v.push_back(LoopVariant::kPaperFringes);
  return v;
}

const char* variant_key(LoopVariant k) {
  switch (k) {
    case LoopVariant::kPaper:
      return "paper";
    case LoopVariant::kImproved:
      return "improved";
    case LoopVariant::kOracleFeedback:
      return "oracle";
    case LoopVariant::kPaperFringes:
      return "paper_fringes";
  }
  return "";
}

const char* variant_label(LoopVariant k) {
  switch (k) {
    case LoopVariant::kPaper:
      return "paper's controller";
    case LoopVariant::kImproved:
      return "improved controller";
    case LoopVariant::kOracleFeedback:
      return "oracle (plate feedback: impossible on hardware)";
    case LoopVariant::kPaperFringes:
      return "paper's controller calibrated from fringes (no XL-80)";
  }
  return "";
}

std::vector<FigureSpec> comparison_figures(const config::ProjectConfig& config) {
  using S = ExperimentSet;
  std::vector<FigureSpec> f{
      {"travel_semi_closed_um", "semi-closed-loop travel", "um",
       from_set([](const S& s) { return figure(s.travel.semi_closed_um, s.travel.validity); }),
       experiments::TravelRangeOptions{}.increment_um},
      {"travel_open_loop_um", "open-loop travel", "um",
       from_set([](const S& s) { return figure(s.travel.open_loop_um, s.travel.validity); })},
      {"step_settling_time_s", "11 µm step, settling to ±2 %", "s", from_set([](const S& s) {
         return figure(s.step.metrics.settling_time_pct_s, s.step.validity);
       })},
      {"step_settling_time_10nm_s", "11 µm step, settling to ±10 nm", "s", from_set([](const S& s) {
         return figure(s.step.metrics.settling_time_abs_s, s.step.validity);
       })},
      {"step_overshoot_pct", "11 µm step, overshoot (interferometer)", "%",
       from_set([](const S& s) { return figure(s.step.metrics.overshoot_pct, s.step.validity); })},
      {"step_truth_overshoot_pct", "11 µm step, overshoot (true plate)", "%",
       from_set([](const S& s) { return figure(s.step.truth_overshoot_pct, s.step.validity); })},
      {"linearity_zero_end_pct", "linearity, the paper's protocol (zero-end)", "%",
       from_set([](const S& s) {
         return figure(s.linearity.metrics.linearity_zero_end_pct, s.linearity.validity);
       })},
      {"linearity_best_fit_pct", "linearity, the paper's protocol (best fit)", "%",
       from_set([](const S& s) {
         return figure(s.linearity.metrics.linearity_best_fit_pct, s.linearity.validity);
       })},
      {"linearity_grid_zero_end_pct", "linearity, unseen 0.25 µm grid (zero-end)", "%",
       from_set([](const S& s) {
         return figure(s.linearity_grid.metrics.linearity_zero_end_pct, s.linearity_grid.validity);
       })},
      {"linearity_down_zero_end_pct", "linearity, downwards (zero-end)", "%",
       from_set([](const S& s) {
         return figure(s.linearity_down.metrics.linearity_zero_end_pct, s.linearity_down.validity);
       })},
      {"repeatability_5um_nm", "repeatability at 5 µm (1 σ)", "nm", from_set([](const S& s) {
         return figure(s.repeat_5um.metrics.repeatability_nm, s.repeat_5um.validity);
       })},
      {"repeatability_10um_nm", "repeatability at 10 µm (1 σ)", "nm", from_set([](const S& s) {
         return figure(s.repeat_10um.metrics.repeatability_nm, s.repeat_10um.validity);
       })},
      {"phase_step_hold_jitter_nm_rms", "λ/8 step, hold jitter of 1 ms means (rms)", "nm",
       from_set([](const S& s) {
         return figure(s.phase_step.hold_jitter_nm_rms, s.phase_step.validity);
       })},
      {"phase_step_settling_time_s", "λ/8 step, settling to ±1 nm (1 ms means)", "s",
       from_set(
           [](const S& s) { return figure(s.phase_step.settling_time_s, s.phase_step.validity); })},
      {"phase_step_final_error_nm", "λ/8 step, final error", "nm", from_set([](const S& s) {
         return figure(s.phase_step.final_error_nm, s.phase_step.validity);
       })},
      {"phase_step_own_settling_time_s",
       "λ/8 step, settling of the step minus the same seed without it (±1 nm)", "s",
       from_set([](const S& s) {
         return figure(s.phase_step.own_settling_time_s, s.phase_step.validity);
       })},
      {"phase_step_still_wander_nm", "λ/8 step's record without the step, largest wander", "nm",
       from_set(
           [](const S& s) { return figure(s.phase_step.still_wander_nm, s.phase_step.validity); })},
      {"phase_step_10kHz_hold_jitter_nm_rms", "λ/8 step at 10 kHz, hold jitter (rms)", "nm",
       at_10kHz(&experiments::PhaseStepResult::hold_jitter_nm_rms)},
      {"phase_step_10kHz_settling_time_s", "λ/8 step at 10 kHz, settling to ±1 nm", "s",
       at_10kHz(&experiments::PhaseStepResult::settling_time_s)},
      {"phase_step_10kHz_own_settling_time_s",
       "λ/8 step at 10 kHz, settling of the step minus the same seed without it", "s",
       at_10kHz(&experiments::PhaseStepResult::own_settling_time_s)},
  };
  const std::vector<double> rates = inner_loop_sample_times_s(config);
  for (std::size_t i = 0; i < rates.size(); ++i) {
    const std::string at = fmt::format("pid_margins_{:g}kHz_", 1e-3 / rates[i]);
    const std::string label = fmt::format("PID at {:g} kHz, ", 1e-3 / rates[i]);
    f.push_back(
        {at + "gain_margin_dB", label + "gain margin (worst actuator)", "dB", margin(i, true)});
    f.push_back({at + "phase_margin_deg", label + "phase margin (worst actuator)", "deg",
                 margin(i, false)});
  }
  return f;
}

FigureValue median_over_seeds(const std::vector<FigureValue>& per_seed,
                              const std::vector<std::uint64_t>& seeds) {
  FigureValue m;
  std::vector<double> v;
  for (std::size_t i = 0; i < per_seed.size(); ++i) {
    const FigureValue& f = per_seed[i];
    if (!f.measured) {
      m.measured = false;
      return m;
    }
    if (!f.validity.valid)
      m.validity.fail(fmt::format("seed {}: {}", seeds.at(i), f.validity.reason));
    else if (!f.not_applicable.empty() && m.not_applicable.empty())
      m.not_applicable = fmt::format("seed {}: {}", seeds.at(i), f.not_applicable);
    else if (f.not_applicable.empty())
      v.push_back(f.value);
  }
  if (!m.validity.valid)
    m.not_applicable.clear();  // a failure is never hidden behind a figure not judged
  if (!m.validity.valid || !m.not_applicable.empty())
    return m;
  if (v.empty()) {
    m.validity.fail("no seed");
    return m;
  }
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  // Infinite (never settled) sorts last and stays infinite in a mean with it.
  m.value = n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  return m;
}

std::size_t ComparisonResult::figure_index(const std::string& key) const {
  for (std::size_t i = 0; i < figures.size(); ++i)
    if (figures[i].key == key)
      return i;
  return figures.size();
}

std::vector<FigureValue> ComparisonResult::per_seed(std::size_t fig, LoopVariant k) const {
  std::vector<FigureValue> out;
  for (const SeedComparison& s : seeds)
    out.push_back(figures.at(fig).of(s[k]));
  return out;
}

std::vector<FigureValue> ComparisonResult::hold_per_seed(HoldVariant v, std::size_t fig) const {
  std::vector<FigureValue> out;
  for (const SeedComparison& s : seeds) {
    const HoldRun& h = s.hold(v);
    out.push_back(figure(h.*kHoldFigures.at(fig).member, h.validity));
  }
  return out;
}

bool ComparisonResult::hold_target_met() const {
  const FigureValue& m = hold_medians[static_cast<std::size_t>(HoldVariant::kImprovedLocked)][0];
  return options.lock && m.measured && m.validity.valid && m.value <= kHoldTarget_nm;
}

bool ComparisonResult::valid() const {
  return invalid_reasons().empty();
}

std::vector<std::string> ComparisonResult::invalid_reasons() const {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < medians.size(); ++i) {
    for (LoopVariant k : variants()) {
      const FigureValue& m = medians[i][static_cast<std::size_t>(k)];
      if (m.measured && !m.validity.valid)
        out.push_back(fmt::format("{}: {}: {}", variant_key(k), figures[i].key, m.validity.reason));
    }
  }
  for (const HoldVariant v : kHoldVariants) {
    for (std::size_t i = 0; i < kHoldFigures.size(); ++i) {
      const FigureValue& m = hold_medians[static_cast<std::size_t>(v)][i];
      if (m.measured && !m.validity.valid)
        out.push_back(
            fmt::format("hold_{}: {}: {}", hold_key(v), kHoldFigures[i].key, m.validity.reason));
    }
  }
  return out;
}

std::vector<std::string> ComparisonResult::not_applicable_reasons() const {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < medians.size(); ++i) {
    for (LoopVariant k : variants()) {
      const FigureValue& m = medians[i][static_cast<std::size_t>(k)];
      if (m.measured && m.validity.valid && !m.not_applicable.empty())
        out.push_back(fmt::format("{}: {}: {}", variant_key(k), figures[i].key, m.not_applicable));
    }
  }
  return out;
}

namespace {

// The improved calibration's verdict on the loop's rate, where it names the plate's mode on
// every seed whose calibration finished (the first seed's sentence); "" otherwise.
std::string named_rate_verdict(const ComparisonResult& r) {
  std::string first;
  for (const SeedComparison& sc : r.seeds) {
    const VariantRun& run = sc[LoopVariant::kImproved];
    if (!run.calibration.valid)
      continue;
    if (!run.rate_verdict.mode_is_the_limit)
      return "";
    if (first.empty())
      first = run.rate_verdict.text();
  }
  return first;
}

// What the improved controller was built to meet: absolute bounds, then bounds relative to the
// oracle's median, then travel and the margins at the config's loop rates.
std::vector<Target> comparison_targets(const config::ProjectConfig& config,
                                       const ComparisonResult& r) {
  std::vector<Target> t{
      target("11 µm step settles to ±10 nm", "step_settling_time_10nm_s", 10e-3, false, "≤ 10 ms"),
      r.rate_verdict.empty()
          ? target("λ/8 step settles to ±1 nm (1 ms means), 1 kHz", "phase_step_settling_time_s",
                   5e-3, false, "≤ 5 ms")
          : target("λ/8 step settles to ±1 nm (1 ms means), 1 kHz", "phase_step_settling_time_s",
                   kModeLimitedPhaseStep_s, false, "≤ 10 ms (the plate's mode, below)"),
      target("λ/8 step settles to ±1 nm (1 ms means), 10 kHz", "phase_step_10kHz_settling_time_s",
             2e-3, false, "≤ 2 ms"),
      target("hold jitter of the 1 ms means", "phase_step_hold_jitter_nm_rms", 0.3, false,
             "≤ 0.3 nm rms"),
      target("linearity, the paper's protocol", "linearity_zero_end_pct", 0.02, false, "≤ 0.02 %"),
      target("linearity, unseen 0.25 µm grid", "linearity_grid_zero_end_pct", 0.02, false,
             "≤ 0.02 %"),
  };
  struct Relative {
    const char* text;
    const char* key;
    const char* not_applicable = "";
  };
  for (const Relative& rel :
       {Relative{"linearity, the paper's protocol, vs the oracle", "linearity_zero_end_pct",
                 kOracleExactOnThePapersLevels},
        Relative{"linearity, unseen 0.25 µm grid, vs the oracle", "linearity_grid_zero_end_pct"},
        Relative{"linearity, downwards, vs the oracle", "linearity_down_zero_end_pct"},
        Relative{"repeatability at 5 µm, vs the oracle", "repeatability_5um_nm"},
        Relative{"repeatability at 10 µm, vs the oracle", "repeatability_10um_nm"}}) {
    Target x = target(rel.text, rel.key, 0.0, false, "");
    const std::size_t i = r.figure_index(rel.key);
    const FigureValue& o = r.medians.at(i)[static_cast<std::size_t>(LoopVariant::kOracleFeedback)];
    x.not_applicable = rel.not_applicable;
    if (!x.not_applicable.empty()) {
      x.bound = -std::numeric_limits<double>::infinity();  // not judged
      x.bound_text = "≤ 1.2 × oracle: not applicable";
    } else if (o.validity.valid) {
      x.bound = 1.2 * o.value;
      x.bound_text = fmt::format("≤ 1.2 × oracle ({})", format_figure(x.bound, r.figures[i].unit,
                                                                      r.figures[i].resolution));
    } else {
      x.bound = -std::numeric_limits<double>::infinity();  // nothing to be within
      x.bound_text = "≤ 1.2 × oracle (oracle not valid)";
    }
    t.push_back(std::move(x));
  }
  if (!r.rate_verdict.empty())
    t[1].bound_reason = "the improved calibration names the plate's mode: " + r.rate_verdict;
  t.push_back(target("semi-closed-loop travel", "travel_semi_closed_um", 12.5, true, "≥ 12.5 µm"));
  for (const double ts : inner_loop_sample_times_s(config)) {
    const std::string at = fmt::format("pid_margins_{:g}kHz_", 1e-3 / ts);
    t.push_back(target(fmt::format("gain margin at {:g} kHz", 1e-3 / ts), at + "gain_margin_dB",
                       6.0, true, "≥ 6 dB"));
    t.push_back(target(fmt::format("phase margin at {:g} kHz", 1e-3 / ts), at + "phase_margin_deg",
                       45.0, true, "≥ 45°"));
  }
  for (Target& x : t) {
    const std::size_t i = r.figure_index(x.key);
    if (x.key.empty() || i == r.figures.size()) {
      x.improved.measured = false;  // compare does not measure it (yet)
      continue;
    }
    x.unit = r.figures[i].unit;
    x.resolution = r.figures[i].resolution;
    x.improved = r.medians[i][static_cast<std::size_t>(LoopVariant::kImproved)];
    const double v = x.improved.value;
    x.met = x.not_applicable.empty() && x.improved.measured && x.improved.validity.valid &&
            std::isfinite(x.bound) && (x.at_least ? v >= x.bound : v <= x.bound);
  }
  return t;
}

// Can fringes replace the XL-80 in the paper's calibration? Per Table 4 figure: the fringe
// column's median against the XL-80 paper
// column's smallest and largest seed. Not judged where a value of either is not a number.
std::vector<SpreadCheck> fringes_within_spread(const ComparisonResult& r) {
  std::vector<SpreadCheck> out;
  for (const char* key : kTable4Figures) {
    SpreadCheck c;
    c.key = key;
    const std::size_t i = r.figure_index(c.key);
    if (i == r.figures.size())
      continue;
    c.fringes_median = r.medians[i][static_cast<std::size_t>(LoopVariant::kPaperFringes)];
    const std::vector<FigureValue> xl80 = r.per_seed(i, LoopVariant::kPaper);
    std::vector<double> v;
    for (std::size_t n = 0; n < xl80.size(); ++n) {
      if (!xl80[n].validity.valid || !xl80[n].not_applicable.empty()) {
        c.not_judged = fmt::format("the XL-80 column is not a number on seed {}", r.seeds[n].seed);
        break;
      }
      v.push_back(xl80[n].value);
    }
    if (c.not_judged.empty() &&
        (!c.fringes_median.validity.valid || !c.fringes_median.not_applicable.empty()))
      c.not_judged = "the fringe column's median is not a number";
    if (c.not_judged.empty() && !v.empty()) {
      const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
      c.xl80_min = *lo;
      c.xl80_max = *hi;
      c.within = c.fringes_median.value >= c.xl80_min && c.fringes_median.value <= c.xl80_max;
    }
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace

ComparisonResult summarize_comparison(const config::ProjectConfig& config,
                                      const CompareOptions& options,
                                      std::vector<SeedComparison> seeds) {
  if (seeds.size() != options.seeds.size())
    throw std::invalid_argument("summarize_comparison: one SeedComparison per seed of the options");
  ComparisonResult r;
  r.options = options;
  r.schedule = options.quick ? Schedule::quick() : Schedule::paper();
  r.figures = comparison_figures(config);
  r.seeds = std::move(seeds);
  for (const SeedComparison& sc : r.seeds)
    for (LoopVariant k : r.variants())
      r.simulated_time_s += sc[k].simulated_time_s;
  for (std::size_t i = 0; i < r.figures.size(); ++i) {
    std::array<FigureValue, kVariantCount>& m = r.medians.emplace_back();
    m.fill(not_measured());
    for (LoopVariant k : r.variants())
      m[static_cast<std::size_t>(k)] = median_over_seeds(r.per_seed(i, k), options.seeds);
  }
  for (auto& per_hold : r.hold_medians)
    per_hold.fill(not_measured());
  if (options.lock) {
    for (const SeedComparison& sc : r.seeds)
      for (const HoldRun& h : sc.holds)
        r.simulated_time_s += h.simulated_time_s;
    for (const HoldVariant v : kHoldVariants)
      for (std::size_t i = 0; i < kHoldFigures.size(); ++i)
        r.hold_medians[static_cast<std::size_t>(v)][i] =
            median_over_seeds(r.hold_per_seed(v, i), options.seeds);
  }
  r.rate_verdict = named_rate_verdict(r);
  r.targets = comparison_targets(config, r);
  if (options.fringes)
    r.fringes_within_spread = fringes_within_spread(r);
  return r;
}

ComparisonResult compare(const config::ProjectConfig& config, const CompareOptions& options,
                         const rig::Progress& progress) {
  if (options.seeds.empty())
    throw std::invalid_argument("compare: no seed");
  if (options.lock && !(options.lock_hold_s > 0.0 && options.lock_hold_s <= 3600.0))
    throw std::invalid_argument("compare: the hold's length is not in (0, 3600] s");
  const auto start = std::chrono::steady_clock::now();
  const Schedule schedule = options.quick ? Schedule::quick() : Schedule::paper();
  std::vector<SeedComparison> seeds;
  for (const std::uint64_t seed : options.seeds)
    seeds.push_back(detail::compare_seed(config, seed, schedule, options, progress));
  ComparisonResult r = summarize_comparison(config, options, std::move(seeds));
  r.wall_time_s = core::seconds_since(start);
  return r;
}

}  // namespace piezoshift::reproduction
