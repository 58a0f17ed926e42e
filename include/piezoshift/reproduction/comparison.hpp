#pragma once
// `piezoshift compare`: three variants of the loop side by side, through the same
// experiments and the same seeds: the paper's controller and the improved one, each calibrated by
// its own procedure and fed by the strain gauges, and the paper's controller fed by the oracle (a
// feedback, not a controller). For each seed s:
//   paper     calibration::calibrate(s) (reproduce()'s), then run_experiment_set(s) and
//             analyze_inner_loop(s)
//   improved  calibration::calibrate_improved(s), then the same set and analysis
//             and the lambda/8 step again at 10 kHz (seed + 85); the improved controller is
//             calibrated again at 10 kHz for its 10 kHz figures
//   oracle    the paper's calibrated gains and A with p = identity, fed the plate's true position
//             (Feedback::kOracle, as reproduce()): impossible on hardware, the floor of any
//             controller fed by the strain gauges; its gains chosen as the improved calibration's
//             stage 0 chooses its own (the ring test on its plate feedback, seed + 93: the
//             paper's where they hold); the same set, no 10 kHz step and no
//             inner-loop analysis of its own
//   paper_fringes  (opt-in, CompareOptions::fringes) the paper's controller calibrated
//             from the Fizeau's fringes with no laser interferometer
//             (instrument::calibrate_twin_from_fringes(s): the twin camera on its defaults, the
//             default surface, stage 1 scoring the paper's gains alone), then everything the
//             paper's variant runs, by the same rules; its simulated time includes the
//             calibration's. Reported beside the others, never targeted.
//   the hold  (opt-in, CompareOptions::lock) the Fizeau's hold on the twin camera with
//             the cavity's drift in the fringes, the paper's and the improved controller each
//             unlocked and locked (comparison_hold.hpp): beside the columns, not one of them.
// so a figure of the paper's controller on seed s is bit for bit reproduce()'s on seed s.
//
// Every figure (travel, the 11 um step, the three linearity sweeps, repeatability at 5 and 10 um,
// the lambda/8 phase step at the DAQ's rate and at 10 kHz, the PID's margins at each loop rate) is
// a number per variant and seed, or not valid with its reason (a calibration that failed makes
// every figure of that variant on that seed not valid). The median over seeds of a figure is not
// valid when any seed's value is not: a failure is never averaged away. One exception (issue
// 31's decision): the paper's 10 kHz figures, when compare's ring test finds the paper's gains
// re-expressed at 10 kHz unstable on the plant, are not applicable with that reason, and do not
// make the comparison not valid (a fixed design the issue does not judge, found unstable by the
// procedure, not by the supervisor).
//
// The targets are what the improved controller was built to meet, judged on the improved
// controller's medians; linearity against the oracle is judged on the unseen grid and downwards: on
// the paper's levels that target is not applicable (Target::not_applicable says why).
#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "piezoshift/calibration/rate_verdict.hpp"
#include "piezoshift/reproduction/comparison_hold.hpp"
#include "piezoshift/reproduction/reproduction.hpp"

namespace piezoshift::reproduction {

struct CompareOptions {
  std::vector<std::uint64_t> seeds{1, 2, 3, 4, 5, 6, 7, 8};
  bool quick = false;  //!< Schedule::quick() instead of Schedule::paper()
  //! A fourth column: the paper's controller calibrated from the Fizeau's fringes.
  //! Off: nothing of it is run or reported, the output is the three columns' bit for bit.
  bool fringes = false;
  //! The Fizeau's hold, unlocked and locked, of the paper's and the improved controller (issue
  //! 29, comparison_hold.hpp). Off: nothing of it is run or reported.
  bool lock = false;
  double lock_hold_s = kDefaultHold_s;  //!< the hold's length [s], in (0, 3600]
};

//! What closes the loop in one column of the comparison: a controller and its feedback.
enum class LoopVariant {
  kPaper = 0,           //!< the paper's controller on the strain gauges
  kImproved = 1,        //!< the improved controller on the strain gauges
  kOracleFeedback = 2,  //!< the paper's gains and A, p = identity, on the plate's true position
  //! the paper's controller calibrated from the Fizeau's fringes, on the strain gauges (opt-in)
  kPaperFringes = 3,
};
//! The variants every comparison runs.
inline constexpr std::array<LoopVariant, 3> kLoopVariants{
    LoopVariant::kPaper, LoopVariant::kImproved, LoopVariant::kOracleFeedback};
inline constexpr std::size_t kVariantCount = 4;
//! The variants a comparison with these options runs and reports, in the report's order:
//! kLoopVariants, then kPaperFringes when options.fringes.
std::vector<LoopVariant> loop_variants(const CompareOptions& options);
//! "paper", "improved", "oracle", "paper_fringes": the JSON prefixes (without the underscore) and
//! file names.
const char* variant_key(LoopVariant k);
//! How the report names it.
const char* variant_label(LoopVariant k);

//! One variant of the loop on one seed.
struct VariantRun {
  control::SemiClosedLoopParams controller;
  //! Not valid when its calibration failed (rig::ProcedureFailed, or calibration::FitError
  //! on the twin's records); nothing ran then.
  rig::Validity calibration;
  ExperimentSet set;
  std::vector<InnerLoopAnalysis> inner_loop;  //!< empty for the oracle
  //! The lambda/8 step again with the loop at 10 kHz (seed + 85): the twin's DAQ at 0.1 ms; the
  //! paper's gains re-expressed per sample (as analyze_inner_loop does), the improved controller
  //! calibrated again at 10 kHz by its own procedure (same seeds), which also gives its 10 kHz
  //! inner-loop analysis. Not valid when the twin cannot run at that rate. Not run for the oracle
  //! (ran_10kHz false): at 10 kHz its plate feedback trips the supervisor's sgs-jump rule in the
  //! approach (docs/compare.md).
  experiments::PhaseStepResult phase_step_10kHz;
  bool ran_10kHz = false;
  //! The paper's controller: why its 10 kHz figures (the step, the margins) are not applicable,
  //! the ring test's reason when its gains re-expressed at 10 kHz ring up ("": they apply).
  std::string not_applicable_10kHz;
  //! The oracle: its holding gains over the paper's calibrated ones (1: the paper's held).
  double holding_gains_scale = 1.0;
  //! The oracle: the modes its feedback's notches remove (folded at its rate), 0 for none: only
  //! where its plain loop held below kOracleNotchBelowScale (comparison.cpp, docs/compare.md).
  std::array<double, 2> feedback_notch_Hz{};
  double simulated_time_s = 0.0;  //!< its calibration and experiments
  //! paper_fringes: the calibration from fringes' wall time.
  double calibration_wall_time_s = 0.0;
  //! The improved controller: its calibration's verdict on the loop's rate (stage 5b,
  //! calibration/rate_verdict.hpp); empty for the others.
  calibration::RateVerdict rate_verdict;
};

struct SeedComparison {
  std::uint64_t seed = 0;
  //! Indexed by LoopVariant; kPaperFringes default-constructed (nothing ran) unless asked for.
  std::array<VariantRun, kVariantCount> runs;
  //! Indexed by HoldVariant; with CompareOptions::lock only (else nothing ran).
  std::array<HoldRun, kHoldVariants.size()> holds;
  const VariantRun& operator[](LoopVariant k) const { return runs[static_cast<std::size_t>(k)]; }
  const HoldRun& hold(HoldVariant v) const { return holds[static_cast<std::size_t>(v)]; }
};

//! One figure of one run: a number (infinite for a time that never came: not settled), or not
//! valid with its reason, or not applicable with its reason (valid, no number: the paper's 10 kHz
//! figures where its gains ring up there), or not measured for that variant (the oracle's
//! margins).
struct FigureValue {
  double value = std::numeric_limits<double>::quiet_NaN();
  rig::Validity validity;
  bool measured = true;
  std::string not_applicable;  //!< why it is not judged ("": it is)
};

struct FigureSpec {
  std::string key;    //!< JSON key after the prefix, unit last: "step_settling_time_10nm_s"
  std::string label;  //!< the report's row
  std::string unit;   //!< shown after the number: "s", "nm", "%", "um", "dB", "deg"
  std::function<FigureValue(const VariantRun&)> of;
  double resolution = 0.0;  //!< the step it is measured in (format_figure); 0: the unit's
};

//! The figures compare reports, in the report's order (the margins at the config's loop rates).
std::vector<FigureSpec> comparison_figures(const config::ProjectConfig& config);

//! The median over seeds of one figure for one variant (the mean of the middle two for an even
//! count). Not valid when a seed's value is not: the reason names the first such seed; else not
//! applicable when a seed's is not, named the same way.
FigureValue median_over_seeds(const std::vector<FigureValue>& per_seed,
                              const std::vector<std::uint64_t>& seeds);

//! The 1 kHz lambda/8 step's bound where the improved calibration names the plate's mode as its
//! limit (a mode near a multiple of the tick rate, or a fold that needs 5 or more taps): such a
//! plate is held to the 10 kHz step's bound at 10 kHz and to this at 1 kHz.
inline constexpr double kModeLimitedPhaseStep_s = 10e-3;

//! One of the improved controller's targets, judged on its median.
struct Target {
  std::string text;         //!< e.g. "11 um step settles to +-10 nm"
  std::string key;          //!< the figure
  std::string unit;         //!< the figure's
  double resolution = 0.0;  //!< the figure's
  std::string bound_text;
  FigureValue improved;   //!< its median (not measured: compare cannot judge it)
  double bound = 0.0;     //!< the limit, absolute or oracle_factor x the oracle's median
  bool at_least = false;  //!< >= bound (travel, margins), else <= bound
  //! Why the target is not judged ("": it is); such a target is never met.
  std::string not_applicable;
  //! Why the bound is not the usual one ("": it is): the 1 kHz lambda/8 step's 10 ms where the
  //! improved calibration names the plate's mode as what limits it.
  std::string bound_reason;
  bool met = false;

  //! "yes", "no", "n/a" (not applicable) or "-" (compare does not measure it).
  const char* verdict() const noexcept;
};

//! The figures of the paper's Table 4 among comparison_figures(): the 11 um step's settling to
//! +-2 %, linearity (zero-end), repeatability at 5 and 10 um.
inline constexpr std::array<const char*, 4> kTable4Figures{
    "step_settling_time_s", "linearity_zero_end_pct", "repeatability_5um_nm",
    "repeatability_10um_nm"};

//! Can fringes replace the XL-80? On one Table 4 figure: is the median of the paper's controller
//! calibrated from fringes within the seed spread (smallest to largest seed) of the same controller
//! calibrated with the XL-80? Reported, not a target.
struct SpreadCheck {
  std::string key;  //!< the figure
  FigureValue fringes_median;
  double xl80_min = 0.0, xl80_max = 0.0;  //!< over the seeds (only if judged)
  //! Why it is not judged ("": it is): a value not valid or not applicable on a seed.
  std::string not_judged;
  bool within = false;
};

struct ComparisonResult {
  CompareOptions options;
  Schedule schedule;
  std::vector<FigureSpec> figures;
  std::vector<SeedComparison> seeds;
  //! [figure][variant]: the median over seeds; not measured for a variant not run.
  std::vector<std::array<FigureValue, kVariantCount>> medians;
  std::vector<Target> targets;
  //! With options.fringes: one per Table 4 figure (kTable4Figures).
  std::vector<SpreadCheck> fringes_within_spread;
  //! With options.lock: [HoldVariant][kHoldFigures] the median over seeds (not measured without).
  std::array<std::array<FigureValue, kHoldFigures.size()>, kHoldVariants.size()> hold_medians;
  double simulated_time_s = 0.0;
  double wall_time_s = 0.0;
  //! The improved calibration's verdict on the loop's rate where it names the plate's mode on
  //! every seed (the first seed's sentence): the 1 kHz lambda/8 step is then held to
  //! kModeLimitedPhaseStep_s. "": it names none (or not on every seed).
  std::string rate_verdict;

  //! loop_variants(options).
  std::vector<LoopVariant> variants() const { return loop_variants(options); }
  //! The index in figures of the figure with this key (figures.size() when none has it).
  std::size_t figure_index(const std::string& key) const;
  //! The per-seed values of one figure of one variant.
  std::vector<FigureValue> per_seed(std::size_t figure, LoopVariant k) const;
  //! The per-seed values of one hold figure (kHoldFigures) of one hold.
  std::vector<FigureValue> hold_per_seed(HoldVariant v, std::size_t figure) const;
  //! The lock's check: the improved controller's locked hold, median RMS, within kHoldTarget_nm
  //! (false without options.lock or when that median is not a number). Reported, not a target.
  bool hold_target_met() const;
  //! Every measured median of every variant valid (and of every hold, with options.lock).
  bool valid() const;
  //! "variant: figure: reason" (variant_key; "hold_<hold_key>" for a hold) for every median that
  //! is not valid.
  std::vector<std::string> invalid_reasons() const;
  //! The same for every median that is not applicable (these leave valid() true).
  std::vector<std::string> not_applicable_reasons() const;
};

//! The figures, their medians over the seeds and the targets, from runs already made (one
//! SeedComparison per seed of options.seeds, in that order): compare()'s second half, apart so
//! that the summary and its report can be checked on runs made up for the purpose.
ComparisonResult summarize_comparison(const config::ProjectConfig& config,
                                      const CompareOptions& options,
                                      std::vector<SeedComparison> seeds);

//! Throws std::invalid_argument on an empty seed list.
ComparisonResult compare(const config::ProjectConfig& config, const CompareOptions& options,
                         const rig::Progress& progress = {});

}  // namespace piezoshift::reproduction
