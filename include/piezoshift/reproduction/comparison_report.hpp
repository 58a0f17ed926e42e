#pragma once
// The outputs of `piezoshift compare` (comparison.hpp):
//   comparison_json()   the medians, keys prefixed paper_, improved_, oracle_ (and with
//                       --fringes paper_fringes_) with the unit last (null: a time that never
//                       came, or a figure not valid; the reason is in <prefix>not_valid), the
//                       targets, and per_seed: one object per seed with the same prefixed keys;
//                       with --fringes also paper_fringes_within_xl80_spread (SpreadCheck);
//                       with --lock hold_<paper|improved>_<unlocked|locked>_<figure> medians,
//                       hold_not_valid, hold_s, hold_improved_locked_within_target, and per
//                       seed the same keys with hold_<...>_frames and hold_wall_s
//   write_comparison_report(dir)
//     comparison.md, comparison.html   the three (four) columns, the targets, the figures
//     compare_step_response.png        the 11 um steps overlaid (first seed)
//     compare_phase_step.png           the lambda/8 steps' 1 ms exposure means (first seed)
//     compare_linearity_error.png      zero-end deviations of the paper's protocol and the grid
//     compare_repeatability.png        histograms at 5 and 10 um, one per controller
//     per_seed_<controller>.csv        one row per seed, one column per figure (nan: not valid)
//     comparison.json                  comparison_json()
// Throws core::InputError when the folder cannot be written and io::PlotError when gnuplot fails.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "piezoshift/reproduction/comparison.hpp"
#include "piezoshift/reproduction/report.hpp"

namespace piezoshift::reproduction {

nlohmann::json comparison_json(const ComparisonResult& r);

//! One row of the report's table of SpreadChecks: the figure, the fringe column's median, the
//! XL-80 column's spread, "yes" / "no" / "not judged: why". compare's terminal prints it too.
std::vector<std::string> spread_row(const ComparisonResult& r, const SpreadCheck& c);

//! compare --lock: "The Fizeau hold, 60 s, cavity drift in the fringes".
std::string hold_title(const ComparisonResult& r);
//! compare --lock: the holds' medians, a row per controller, a column per figure unlocked and
//! locked ("NOT VALID" for a median that is not; the reasons are invalid_reasons()'s).
std::vector<std::vector<std::string>> hold_median_table(const ComparisonResult& r);
//! compare --lock: the lock's check on the improved controller's locked median, one line.
std::string hold_check_text(const ComparisonResult& r);

//! Where the improved calibration names the plate's mode on every seed: the 1 kHz lambda/8
//! step's 10 ms bound and the calibration's sentence (the mode, the step it allows at 1 kHz, the
//! rate that meets 5 ms); "" otherwise. The report and compare's terminal print it.
std::string rate_verdict_text(const ComparisonResult& r);

//! config_label says where the configuration came from (a path, or the built-in defaults).
ReportFiles write_comparison_report(const ComparisonResult& r, const std::filesystem::path& dir,
                                    const std::string& config_label);

}  // namespace piezoshift::reproduction
