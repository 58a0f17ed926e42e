#include "comparison_seed.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include <fmt/core.h>

#include "piezoshift/calibration/fit_error.hpp"
#include "piezoshift/calibration/holding_gains.hpp"
#include "piezoshift/calibration/improved_calibration.hpp"
#include "piezoshift/control/notch_filter.hpp"
#include "piezoshift/instrument/fringe_calibration.hpp"

namespace piezoshift::reproduction::detail {
namespace {

using rig::Validity;

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

// The paper's gains re-expressed at 10 kHz ring up at the mode of a thicker or heavier
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

// The oracle closes the paper's gains around the plate's true position, which sees the
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

// The paper's controller calibrated from the Fizeau's fringes instead of the XL-80, as
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

// The Fizeau's hold of the paper's and the improved controller, unlocked and locked
// (comparison_hold.hpp); one progress label each.
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
}  // namespace

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
    improved.rate_verdict = cal.rate_verdict;
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
    // A fixed design (the paper's 1 kHz gains re-expressed), not what is judged here, found
    // unstable by the
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

}  // namespace piezoshift::reproduction::detail
