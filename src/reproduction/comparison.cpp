#include "piezoshift/reproduction/comparison.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <utility>

#include <fmt/core.h>

#include "piezoshift/calibration/fit_error.hpp"
#include "piezoshift/calibration/holding_gains.hpp"
#include "piezoshift/calibration/improved_calibration.hpp"
#include "piezoshift/control/notch_filter.hpp"
#include "piezoshift/core/wall_time.hpp"
#include "piezoshift/instrument/fringe_calibration.hpp"
#include "piezoshift/reproduction/figure_format.hpp"

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

// Issue 31: linearity against the oracle is judged on the unseen grid and downwards, not on the
// paper's whole-micron levels, where the oracle reads exactly 0 and 1.2 x 0 asks for exactly 0.
constexpr const char* kOracleExactOnThePapersLevels =
    "the oracle reads exactly 0 on the paper's whole-micron levels (its plate held on the levels "
    "the interferometer reads to 1 nm), so 1.2 × 0 would ask for exactly 0; judged on the 0.25 µm "
    "grid and downwards instead (issue 31)";

// The lambda/8 step with the loop at 10 kHz: the same controller re-expressed per sample.
experiments::PhaseStepResult phase_step_at_10kHz(const config::ProjectConfig& config,
                                                 const control::SemiClosedLoopParams& controller,
                                                 std::uint64_t seed,
                                                 const experiments::PhaseStepOptions& options,
                                                 const rig::Progress& progress) {
  config::ProjectConfig at = config;
  control::SemiClosedLoopParams c = controller;
  at.twin.daq.sample_time_s = c.sample_time_s = kFastSampleTime_s;
  try {
    return experiments::run_phase_step(at, c, seed, options, progress);
  } catch (const std::invalid_argument& e) {  // e.g. a physics rate 10 kHz does not divide
    experiments::PhaseStepResult r;
    r.validity.fail(e.what());
    return r;
  }
}

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

// How a calibration that cannot finish is reported: that variant's seed is not valid, the
// others still run.
template <class Calibrate>
void calibrate_or_fail(Validity& validity, const char* what, Calibrate&& calibrate) {
  try {
    calibrate();
  } catch (const rig::ProcedureFailed& e) {
    validity.fail(fmt::format("{}: {}", what, e.what()));
  } catch (const calibration::FitError& e) {  // the twin's records, not the user's input
    validity.fail(fmt::format("{}: a fit failed: {}", what, e.what()));
  }
}

// The twin at 10 kHz, its interferometer's dynamic mode at the loop's rate (an XL-80 samples up
// to 50 kHz), so the improved calibration sees the plate's mode below its Nyquist frequency.
config::ProjectConfig at_10kHz(const config::ProjectConfig& config) {
  config::ProjectConfig at = config;
  at.twin.daq.sample_time_s = kFastSampleTime_s;
  at.twin.interferometer.dynamic_sample_rate_Hz =
      std::max(at.twin.interferometer.dynamic_sample_rate_Hz, 1.0 / kFastSampleTime_s);
  return at;
}

// Issue 31: the paper's gains re-expressed at 10 kHz ring up at the mode of a thicker or heavier
// plate. A ring test (calibration/holding_gains.hpp, at the gains themselves, seed + 92) finds it
// before the 10 kHz identification and phase step would excite it and trip the supervisor: a
// ring that grows (or that the test had to open) is the reason those figures are not valid. It
// only reads the plant, so where the loop holds nothing else changes. Empty: the loop holds.
std::string paper_unstable_at_10kHz(const config::ProjectConfig& config,
                                    const control::SemiClosedLoopParams& controller,
                                    std::uint64_t seed) {
  control::SemiClosedLoopParams fast = controller;
  fast.sample_time_s = kFastSampleTime_s;
  // Unstable is a ring that grows: the ring test's own criterion with a decay of 1 and no noise
  // allowance (a ring at the gauges' noise that grows still grows).
  calibration::RingTestOptions grows;
  grows.decay_ratio = 1.0;
  grows.noise_factor = 0.0;
  calibration::RingTest t;
  try {
    t = calibration::ring_test(at_10kHz(config), fast, seed + 92, grows);
  } catch (const std::invalid_argument&) {  // the twin cannot run at 10 kHz: said below
    return {};
  }
  if (t.holds)
    return {};
  return fmt::format(
      "the paper's gains re-expressed at 10 kHz are unstable on this plant: a 0.5 µm step's ring "
      "at the gauges {} (rms of the second difference {:.3g} µm at 10-30 ms{}); not run",
      t.aborted ? "grew until the ring test opened the loop" : "grew", t.early_ring_um,
      t.aborted ? "" : fmt::format(", {:.3g} µm at 40-60 ms", t.late_ring_um));
}

// The 10 kHz figures of the paper's or the improved controller: its inner loop at 10 kHz and
// the lambda/8 step with the loop at that rate.
void run_at_10kHz(const config::ProjectConfig& config, const control::SemiClosedLoopParams& base,
                  std::uint64_t seed, const Schedule& s, LoopVariant k, VariantRun& run,
                  const rig::Progress& progress) {
  // The paper's gains are re-expressed per sample at 10 kHz (as reproduce() does); the
  // improved controller's models are sampled at their rate, so its own procedure calibrates
  // it again there (same seeds) for the 10 kHz figures.
  control::SemiClosedLoopParams fast = run.controller;
  fast.sample_time_s = kFastSampleTime_s;
  const config::ProjectConfig at = at_10kHz(config);
  if (k == LoopVariant::kImproved && config.twin.daq.sample_time_s != kFastSampleTime_s) {
    try {
      control::SemiClosedLoopParams fast_base = base;
      fast_base.sample_time_s = kFastSampleTime_s;
      calibration::ImprovedCalibrationOptions io_opts;
      io_opts.paper = s.calibration;
      calibrate_or_fail(run.phase_step_10kHz.validity, "calibration at 10 kHz", [&] {
        fast = calibration::calibrate_improved(at, fast_base, seed, io_opts, progress).controller;
      });
    } catch (const std::invalid_argument& e) {  // the twin cannot run at 10 kHz
      run.phase_step_10kHz.validity.fail(e.what());
    }
  }
  run.ran_10kHz = true;
  if (!run.phase_step_10kHz.validity.valid) {
    for (InnerLoopAnalysis& a : run.inner_loop)
      if (a.sample_time_s == kFastSampleTime_s)
        a.validity.fail(run.phase_step_10kHz.validity.reason);
    return;
  }
  for (std::size_t i = 0; i < run.inner_loop.size(); ++i) {
    if (run.inner_loop[i].sample_time_s == kFastSampleTime_s && k == LoopVariant::kImproved)
      run.inner_loop[i] = analyze_inner_loop_at(config, fast, kFastSampleTime_s, seed + 90 + i);
  }
  run.phase_step_10kHz = phase_step_at_10kHz(config, fast, seed + 85, s.phase_step, progress);
  run.simulated_time_s += run.phase_step_10kHz.simulated_time_s;
}

// Issue 31: the oracle closes the paper's gains around the plate's true position, which sees the
// plate's mode with no stack in between, and at 1 kHz that loop rings up on plates lighter or
// heavier than the default's. It chooses the gains it holds with as the improved calibration's
// stage 0 does (holding_gains.hpp: the ring test, here on its own plate
// feedback, scaled down by 0.7 a try until 1.5 x them holds; seed + 93), or the calibration
// fails with that procedure's reason. Where the paper's gains hold, the oracle is what it was,
// bit for bit.
//
// Below kOracleNotchBelowScale the scaled loop is too slow for the supervisor's tracking rule
// (|S - y| > 1 um for 0.1 s) on the schedule's 11 um moves (measured: 0.49 x runs the whole
// schedule on payload and soft-hysteresis, 0.17 x trips it on contact-spread). There the ring the
// paper's gains rang with is identified (its folded frequency, holding_gains' first test) and
// taken out of the oracle's feedback by a notch (control/notch_filter.hpp), the ladder run again
// on that loop; the notched gains are kept when they hold at a larger scale, and a second notch
// goes on the ring that loop's first test rang with, while the scale is still below it. Above it
// nothing changes, so every oracle that held at 0.49 x or more is the same bit for bit.
constexpr double kOracleNotchBelowScale = 0.4;
constexpr double kOracleNotchPoleRadius = 0.85;  // about 50 Hz wide at 1 kHz

Schedule with_oracle_notch(Schedule s, const control::OracleNotches& notch) {
  for (rig::BenchOptions* b :
       {&s.travel.bench, &s.step.bench, &s.linearity.bench, &s.linearity_grid.bench,
        &s.linearity_down.bench, &s.phase_step.bench, &s.repeat_5um.bench, &s.repeat_10um.bench})
    b->oracle_notch = notch;
  return s;
}

void choose_oracle_gains(const config::ProjectConfig& config, std::uint64_t seed,
                         Schedule& oracle_schedule, VariantRun& oracle) {
  calibration::HoldingGainsOptions o;
  o.ring.bench = oracle_schedule.phase_step.bench;  // the oracle's feedback and supervisor
  // Tested at 1.5 x, not stage 0's 2 x: the default twin's oracle holds at 1.5 x and rings at 2 x
  // (seed 1: the ring's rms 0.138 -> 0.016 um, and 0.41 -> 0.38 um), so 2 x would retune the
  // oracle the comparison was built on; 1.5 x (3.5 dB) still covers the stack's slope at the end
  // of a stroke (1.25, 1.9 dB), where the oracle's travel and 11 um step take it.
  o.margin_factor = 1.5;
  const std::string what = "the oracle's holding gains (its plate feedback)";
  calibration::HoldingGains h =
      calibration::holding_gains(config, oracle.controller, seed + 93, o, what);
  // Each pass notches the ring the last ladder's first test rang with, while that raises the scale.
  control::OracleNotches notches{};
  for (std::size_t n = 0; n < notches.size() && h.scale < kOracleNotchBelowScale; ++n) {
    if (!(h.first.ring_Hz > 0.0))
      break;
    control::OracleNotches trial = notches;
    trial[n] = control::NotchParams{h.first.ring_Hz, kOracleNotchPoleRadius};
    calibration::HoldingGainsOptions on = o;
    on.ring.bench.oracle_notch = trial;
    try {
      const calibration::HoldingGains hn =
          calibration::holding_gains(config, oracle.controller, seed + 93, on, what);
      if (!(hn.scale > h.scale))
        break;
      h = hn;
      notches = trial;
    } catch (const rig::ProcedureFailed&) {
      break;  // the notched loop holds nowhere: the last gains stand
    }
  }
  if (notches[0].mode_Hz > 0.0) {
    oracle.feedback_notch_Hz = {notches[0].mode_Hz, notches[1].mode_Hz};
    oracle_schedule = with_oracle_notch(std::move(oracle_schedule), notches);
  }
  oracle.holding_gains_scale = h.scale;
  if (h.scale < 1.0) {
    oracle.controller.gains = h.gains;  // per sample at its own rate
    oracle.controller.gains_sample_time_s = oracle.controller.sample_time_s;
  }
}

// Issue 29: the paper's controller calibrated from the Fizeau's fringes instead of the XL-80, as
// `calibrate --interferometer fizeau --camera twin` runs it (the twin camera on its defaults, the
// default surface drawn from the seed, stage 1 keeping the paper's gains, scored alone: it reads
// no interferometer, and the XL-80 column keeps the same gains), on the supervisor's limits the
// XL-80 column calibrates with.
void calibrate_from_fringes(const config::ProjectConfig& config, std::uint64_t seed,
                            const Schedule& s, const rig::Progress& progress, VariantRun& run) {
  constexpr const char* what = "calibration from fringes";
  calibrate_or_fail(run.calibration, what, [&] {
    camera::InstrumentConfig ic;
    ic.installation.project = config;
    ic.installation.safety = s.calibration.limits;
    const instrument::FringeCalibrationOutcome f = instrument::calibrate_twin_from_fringes(
        ic, seed, psi::SurfaceSpec{},
        instrument::fringe_calibration_options(false, s.calibration.limits), progress);
    run.calibration_wall_time_s = f.wall_time_s;
    run.simulated_time_s =
        f.pid.simulated_time_s + f.matrix.simulated_time_s + f.polynomial.simulated_time_s;
    if (!f.validity.valid) {
      run.calibration.fail(fmt::format("{}: {}", what, f.validity.reason));
      return;
    }
    run.controller = f.controller;
  });
}

// The Fizeau's hold of the paper's and the improved controller, unlocked and locked (issue 29,
// comparison_hold.hpp); one progress label each.
void run_holds(const config::ProjectConfig& config, const CompareOptions& options,
               const rig::Progress& progress, SeedComparison& sc) {
  for (const HoldVariant v : kHoldVariants) {
    const VariantRun& run = sc[hold_of_improved(v) ? LoopVariant::kImproved : LoopVariant::kPaper];
    if (progress)
      progress(0.0, 1.0, fmt::format("seed {} hold: {}", sc.seed, hold_key(v)));
    sc.holds[static_cast<std::size_t>(v)] = run_hold(config, run.controller, run.calibration,
                                                     sc.seed, hold_locked(v), options.lock_hold_s);
  }
}

// The variants on one seed: the paper's and the improved controller each calibrated by its own
// procedure, the oracle feedback on the paper's calibration, and (fringes) the paper's controller
// calibrated from fringes; then (lock) the holds.
SeedComparison compare_seed(const config::ProjectConfig& config, std::uint64_t seed,
                            const Schedule& s, const CompareOptions& options,
                            const rig::Progress& progress) {
  control::SemiClosedLoopParams base{};
  base.sample_time_s = config.twin.daq.sample_time_s;  // as reproduce(): the DAQ's rate
  SeedComparison sc;
  sc.seed = seed;
  const auto labelled = [&](LoopVariant k) -> rig::Progress {
    if (!progress)
      return {};
    return [&progress, seed, k](double done, double total, std::string_view label) {
      progress(done, total, fmt::format("seed {} {}: {}", seed, variant_key(k), label));
    };
  };
  VariantRun& paper = sc.runs[0];
  VariantRun& improved = sc.runs[1];
  VariantRun& oracle = sc.runs[2];
  double paper_calibration_s = 0.0;
  calibrate_or_fail(paper.calibration, "calibration", [&] {
    const calibration::CalibrationOutcome cal =
        calibration::calibrate(config, base, seed, s.calibration, labelled(LoopVariant::kPaper));
    paper.controller = cal.controller;
    paper_calibration_s =
        cal.pid.simulated_time_s + cal.matrix.simulated_time_s + cal.polynomial.simulated_time_s;
  });
  calibrate_or_fail(improved.calibration, "calibration", [&] {
    calibration::ImprovedCalibrationOptions io_opts;
    io_opts.paper = s.calibration;
    const calibration::ImprovedCalibrationOutcome cal = calibration::calibrate_improved(
        config, base, seed, io_opts, labelled(LoopVariant::kImproved));
    improved.controller = cal.controller;
    const auto& m = cal.static_map;
    improved.simulated_time_s =
        m.pid.simulated_time_s + m.matrix.simulated_time_s + m.polynomial.simulated_time_s;
  });
  if (options.fringes)
    calibrate_from_fringes(config, seed, s, labelled(LoopVariant::kPaperFringes),
                           sc.runs[static_cast<std::size_t>(LoopVariant::kPaperFringes)]);
  oracle.calibration = paper.calibration;
  oracle.controller = paper.controller;
  oracle.controller.polynomial = control::CubicPolynomial::identity();
  paper.simulated_time_s = paper_calibration_s;

  Schedule oracle_schedule = with_feedback(s, rig::Feedback::kOracle);
  if (oracle.calibration.valid)
    calibrate_or_fail(oracle.calibration, "calibration",
                      [&] { choose_oracle_gains(config, seed, oracle_schedule, oracle); });
  for (LoopVariant k : loop_variants(options)) {
    VariantRun& run = sc.runs[static_cast<std::size_t>(k)];
    if (!run.calibration.valid)
      continue;
    const bool is_oracle = k == LoopVariant::kOracleFeedback;
    run.set = run_experiment_set(config, run.controller, seed, is_oracle ? oracle_schedule : s,
                                 labelled(k));
    run.simulated_time_s += run.set.experiments_simulated_time_s();
    if (is_oracle)
      continue;
    const bool at_two_rates = config.twin.daq.sample_time_s != kFastSampleTime_s;
    // The paper's design whichever interferometer calibrated it: the same rule at 10 kHz.
    const bool papers = k == LoopVariant::kPaper || k == LoopVariant::kPaperFringes;
    const std::string unstable = papers && at_two_rates
                                     ? paper_unstable_at_10kHz(config, run.controller, seed)
                                     : std::string{};
    if (unstable.empty()) {
      run.inner_loop = analyze_inner_loop(config, run.controller, seed);
      run_at_10kHz(config, base, seed, s, k, run, labelled(k));
      continue;
    }
    // Issue 31's decision: a fixed design the issue does not judge, found unstable by the
    // procedure: its 10 kHz figures are not applicable, not a failure of the comparison.
    run.inner_loop = analyze_inner_loop(config, run.controller, seed, unstable);
    run.ran_10kHz = true;
    run.phase_step_10kHz.validity.fail(unstable);
    run.not_applicable_10kHz = unstable;
  }
  if (options.lock)
    run_holds(config, options, progress, sc);
  return sc;
}

// Issue 12's done-when criteria, as restated: absolute bounds, then bounds relative to the
// oracle's median, then travel and the margins at the config's loop rates.
std::vector<Target> comparison_targets(const config::ProjectConfig& config,
                                       const ComparisonResult& r) {
  std::vector<Target> t{
      target("11 µm step settles to ±10 nm", "step_settling_time_10nm_s", 10e-3, false, "≤ 10 ms"),
      target("λ/8 step settles to ±1 nm (1 ms means), 1 kHz", "phase_step_settling_time_s", 5e-3,
             false, "≤ 5 ms"),
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

// Issue 29's done-when, per Table 4 figure: the fringe column's median against the XL-80 paper
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
    seeds.push_back(compare_seed(config, seed, schedule, options, progress));
  ComparisonResult r = summarize_comparison(config, options, std::move(seeds));
  r.wall_time_s = core::seconds_since(start);
  return r;
}

}  // namespace piezoshift::reproduction
