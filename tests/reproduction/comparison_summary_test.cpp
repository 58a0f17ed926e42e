// compare()'s summary (medians over seeds, targets), its JSON and its report, on runs made up for
// the purpose: the code `compare` runs after its simulations, in milliseconds, so it also runs
// under the sanitizers (the quick compare itself is an acceptance test, release only).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

#include "piezoshift/reproduction/comparison.hpp"
#include "piezoshift/reproduction/comparison_report.hpp"

namespace piezoshift::reproduction {
namespace {

FigureValue value(double v) {
  FigureValue f;
  f.value = v;
  return f;
}

TEST(ComparisonSummary, MedianOfOddAndEvenCounts) {
  EXPECT_EQ(median_over_seeds({value(3.0), value(1.0), value(2.0)}, {1, 2, 3}).value, 2.0);
  EXPECT_EQ(median_over_seeds({value(4.0), value(1.0), value(2.0), value(3.0)}, {1, 2, 3, 4}).value,
            2.5);
  // A step that never settled on most seeds: the median never settled either.
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(std::isinf(median_over_seeds({value(inf), value(1.0), value(inf)}, {1, 2, 3}).value));
}

TEST(ComparisonSummary, AMedianWithAnInvalidSeedIsNotValidAndNamesIt) {
  FigureValue bad;
  bad.validity.fail("step: supervisor tripped");
  const FigureValue m = median_over_seeds({value(1.0), bad, value(2.0)}, {4, 5, 6});
  EXPECT_FALSE(m.validity.valid);
  EXPECT_TRUE(std::isnan(m.value));
  EXPECT_EQ(m.validity.reason, "seed 5: step: supervisor tripped");
}

// Two seeds on which no controller could be calibrated: every median is not valid and names the
// first seed, no target is met, and the JSON and the report say so instead of printing numbers.
ComparisonResult nothing_calibrated() {
  CompareOptions o;
  o.quick = true;
  o.seeds = {7, 9};
  std::vector<SeedComparison> seeds(2);
  for (std::size_t s = 0; s < seeds.size(); ++s) {
    seeds[s].seed = o.seeds[s];
    for (VariantRun& run : seeds[s].runs)
      run.calibration.fail("calibration: made up for the test");
  }
  return summarize_comparison(config::ProjectConfig{}, o, std::move(seeds));
}

TEST(ComparisonSummary, RunsThatFailedTheirCalibrationMakeEveryMeasuredMedianNotValid) {
  const ComparisonResult r = nothing_calibrated();
  EXPECT_FALSE(r.valid());
  ASSERT_EQ(r.medians.size(), r.figures.size());
  std::size_t measured = 0;
  for (const auto& m : r.medians) {
    for (const FigureValue& f : m) {
      if (!f.measured)
        continue;
      ++measured;
      EXPECT_FALSE(f.validity.valid);
      EXPECT_TRUE(std::isnan(f.value));
      EXPECT_EQ(f.validity.reason, "seed 7: calibration: made up for the test");
    }
  }
  EXPECT_GT(measured, 3 * 10U);
  EXPECT_FALSE(r.targets.empty());
  for (const Target& t : r.targets)
    EXPECT_FALSE(t.met) << t.text;
}

TEST(ComparisonSummary, TargetsRelativeToAnOracleThatIsNotValidCannotBeMet) {
  const ComparisonResult r = nothing_calibrated();
  bool found = false;
  for (const Target& t : r.targets) {
    if (t.key == "repeatability_5um_nm" && t.bound_text.find("oracle") != std::string::npos) {
      found = true;
      EXPECT_EQ(t.bound, -std::numeric_limits<double>::infinity());
      EXPECT_EQ(t.bound_text, "≤ 1.2 × oracle (oracle not valid)");
    }
    if (t.key == "travel_semi_closed_um") {
      EXPECT_EQ(t.bound, 12.5);
      EXPECT_TRUE(t.at_least);
    }
  }
  EXPECT_TRUE(found);
}

// Issue 31: linearity against the oracle is judged on the grid and downwards; on the paper's
// whole-micron levels, where the oracle reads exactly 0, the target is not applicable and says why.
TEST(ComparisonSummary, TheOraclesExactZeroIsNotATarget) {
  const ComparisonResult r = nothing_calibrated();
  int relative_linearity = 0;
  for (const Target& t : r.targets) {
    if (t.text.find("linearity") == std::string::npos || t.text.find("oracle") == std::string::npos)
      continue;
    ++relative_linearity;
    if (t.key == "linearity_zero_end_pct") {
      EXPECT_NE(t.not_applicable.find("exactly 0"), std::string::npos) << t.not_applicable;
      EXPECT_STREQ(t.verdict(), "n/a");
    } else {
      EXPECT_TRUE(t.not_applicable.empty()) << t.key;
      EXPECT_STREQ(t.verdict(), "no");  // its median is not valid here
    }
  }
  EXPECT_EQ(relative_linearity, 3);  // the paper's levels (n/a), the grid, downwards
  const nlohmann::json j = comparison_json(r);
  bool found = false;
  for (const auto& t : j["targets"])
    if (t["key"] == "improved_linearity_zero_end_pct" && t.contains("not_applicable"))
      found = !t["met"].get<bool>();
  EXPECT_TRUE(found);
}

TEST(ComparisonSummary, AFigureNotValidIsNullWithItsReasonInTheJson) {
  const nlohmann::json j = comparison_json(nothing_calibrated());
  EXPECT_FALSE(j["valid"].get<bool>());
  ASSERT_TRUE(j.contains("paper_repeatability_10um_nm"));
  EXPECT_TRUE(j["paper_repeatability_10um_nm"].is_null());
  EXPECT_EQ(j["paper_not_valid"]["repeatability_10um_nm"],
            "seed 7: calibration: made up for the test");
  ASSERT_EQ(j["per_seed"].size(), 2U);
  EXPECT_EQ(j["per_seed"][1]["seed"], 9);
}

TEST(ComparisonSummary, OneSeedPerSeedOfTheOptionsOrItIsRefused) {
  CompareOptions o;
  o.seeds = {1, 2};
  EXPECT_THROW(summarize_comparison(config::ProjectConfig{}, o, std::vector<SeedComparison>(1)),
               std::invalid_argument);
}

TEST(ComparisonSummary, TheReportOfRunsThatFailedIsWrittenAndSaysWhy) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / "piezoshift_comparison_summary_test";
  std::filesystem::remove_all(dir);
  // It threw "repeatability figure: no data sets" before the figures learnt to skip such runs.
  const ReportFiles f = write_comparison_report(nothing_calibrated(), dir, "made-up runs");
  EXPECT_TRUE(f.figures.empty());
  ASSERT_TRUE(std::filesystem::exists(dir / "comparison.md"));
  EXPECT_TRUE(std::filesystem::exists(dir / "comparison.html"));
  std::ifstream md(dir / "comparison.md");
  const std::string text{std::istreambuf_iterator<char>(md), std::istreambuf_iterator<char>()};
  EXPECT_NE(text.find("made up for the test"), std::string::npos);
  EXPECT_NE(text.find("no controller was calibrated on any seed"), std::string::npos);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace piezoshift::reproduction
