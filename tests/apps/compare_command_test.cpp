// `piezoshift compare` as a user runs it.
#include <nlohmann/json.hpp>

#include "../support/cli_test.hpp"
#include "../support/svg_text_check.hpp"

namespace piezoshift {
namespace {

using CompareCommand = testing::CliTest;

TEST_F(CompareCommand, QuickRunPrintsTheMediansAndWritesTheReport) {
  const std::string out = path("cmp");
  const testing::CliResult r = run("compare --quick --seeds 2 --json --out '" + out + "'");
  // 0, or 4 when a median is not valid (the JSON and the report are still written).
  ASSERT_TRUE(r.status == 0 || r.status == 4) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(r.status == 0, j["valid"].get<bool>()) << r.err;
  EXPECT_TRUE(j["paper_not_valid"].empty()) << j["paper_not_valid"];
  EXPECT_EQ(j["seeds"], nlohmann::json::array({2}));
  EXPECT_EQ(j["schedule"], "quick");
  // The paper's controller on the twin: 11.5 um semi-closed (Section 4.1), and the oracle's 1 ms
  // means jitter less than the paper's loop, which feeds the gauges' noise into the plate.
  EXPECT_NEAR(j["paper_travel_semi_closed_um"].get<double>(), 11.5, 0.5);
  EXPECT_LT(j["oracle_phase_step_hold_jitter_nm_rms"].get<double>(),
            j["paper_phase_step_hold_jitter_nm_rms"].get<double>());
  EXPECT_TRUE(j.contains("improved_step_settling_time_10nm_s"));
  EXPECT_EQ(j["per_seed"].size(), 1U);
  for (const char* f :
       {"comparison.md", "comparison.html", "comparison.json", "per_seed_paper.csv",
        "per_seed_oracle.csv", "compare_step_response.png", "compare_phase_step.png",
        "compare_linearity_error.png", "compare_repeatability.png"})
    EXPECT_TRUE(std::filesystem::exists(out + "/" + f)) << f;
  // Issue 32: each figure also as SVG, whose text does not overlap and whose axes have units.
  int figures = 0;
  std::string problems;
  for (const std::string& p : testing::folder_figure_problems(out, figures))
    problems += p + "\n";
  EXPECT_EQ(problems, "");
  EXPECT_EQ(figures, 4);
}

TEST_F(CompareCommand, ABadSeedListExitsWithStatusTwoNamingTheOption) {
  for (const char* bad : {"3-1", "x", "1,1", "1-", "-3", "1,,2", "0-100000", ""}) {
    const testing::CliResult r = run(std::string("compare --quick --seeds '") + bad + "'");
    EXPECT_EQ(r.status, 2) << bad;
    EXPECT_NE(r.err.find("--seeds"), std::string::npos) << bad << ": " << r.err;
  }
  const std::string cfg = write("bad.toml", "[twin.piezo]\nfree_stroke_scale = [1, -1, 1]\n");
  const testing::CliResult r = run("compare --quick --seeds 1 --config '" + cfg + "'");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("bad.toml"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace piezoshift
