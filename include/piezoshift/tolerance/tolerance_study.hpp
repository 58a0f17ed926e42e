#pragma once
// One sample of a tolerance study (docs/tolerance.md): a plant drawn from the
// tolerances, its design evaluated (Eqs. 1-4: first mode, hinge stress), its twin calibrated by
// the chosen procedure and measured by a quick experiment set, each through the machinery
// `reproduce` and `compare` use (calibration::calibrate or calibrate_improved, then the
// experiments on the seeds run_experiment_set gives them: travel seed + 10, step + 20,
// linearity + 30, repeatability + 40). Every sample uses the study's seed for the twin's noise
// (common random numbers: two samples differ only by their tolerances), and its deviations come
// from (seed, index) alone, so a sample is the same whichever process or shard runs it.
//
// A sample whose plant cannot be built, whose calibration fails or whose experiment is not valid
// is not valid, with its reason; its metrics that were not measured are NaN, and it fails any
// spec (never dropped).
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "piezoshift/config/project_config.hpp"
#include "piezoshift/reproduction/reproduction.hpp"
#include "piezoshift/tolerance/tolerance_file.hpp"

namespace piezoshift::tolerance {

enum class Procedure { kPaper, kImproved };
const char* procedure_name(Procedure p);
//! The procedure procedure_name() calls `name`; nothing for another name.
std::optional<Procedure> procedure_named(std::string_view name);

//! What each sample measures: the quick set (quick_schedule(), about 0.45 s of CPU a sample), or
//! Table 4's (table4_schedule(): the paper's protocols whole, with repeatability at 10 um too).
enum class ExperimentSet { kQuick, kTable4 };
const char* experiment_set_name(ExperimentSet e);
//! The set experiment_set_name() calls `name`; nothing for another name.
std::optional<ExperimentSet> experiment_set_named(std::string_view name);

//! The metrics every sample records, in this order.
struct Metric {
  const char* key;    //!< "first_mode_Hz": JSON and CSV column, the spec's <key>_min / _max
  const char* label;  //!< the report's
  const char* axis;   //!< a figure's axis, with its unit: "first mode [Hz]"
};
const std::vector<Metric>& metrics();

struct StudyOptions {
  std::uint64_t seed = 1;
  Procedure procedure = Procedure::kPaper;
  ExperimentSet experiments = ExperimentSet::kQuick;
};

//! What the calibration set to absorb the sample's deviations (the lens designer's compensators):
//! the transmission matrix A (Eq. 8, row-major) and p(6 um), the command Z_S the polynomial gives
//! for a desired 6 um (mid-travel), in this order. NaN when the calibration failed.
struct Compensator {
  const char* key;  //!< "A11", ..., "A33", "p_6um_um": the sample record's `calibration` keys
};
const std::vector<Compensator>& compensators();

struct SampleResult {
  std::uint64_t index = 0;
  std::vector<double> deviations;    //!< per tolerance of the set
  std::vector<double> metrics;       //!< per metrics(); NaN where not measured or not valid
  std::vector<double> compensators;  //!< per compensators(); NaN where not calibrated
  bool valid = true;
  std::string reason;  //!< why not valid ("" when valid)
};

//! The quick set's schedule: Schedule::quick() with the paper's gains (no PID grid), its
//! linearity (the paper's levels held 4 s), repeatability of 40 moves, a 0.5 s step record.
reproduction::Schedule quick_schedule();
//! Table 4's: Schedule::paper() (the paper's protocols: linearity held 10 s a level, 230 moves at
//! 5 and at 10 um) with the paper's gains, as the quick set (a PID grid per sample would measure
//! the search, not the tolerances).
reproduction::Schedule table4_schedule();

//! Builds, calibrates and measures the plant of one set of deviations.
SampleResult run_sample(const config::ProjectConfig& nominal, const ToleranceSet& set,
                        const std::vector<double>& deviations, std::uint64_t index,
                        const StudyOptions& options);

}  // namespace piezoshift::tolerance
