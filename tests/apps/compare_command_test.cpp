// `piezoshift compare` as a user runs it.
#include <algorithm>

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

// --fringes (issue 29) is taken, and the physics-step budget counts its column: a budget of 1
// refuses both before anything runs, naming the quick estimates (5.02e3 and 6.68e3 s a seed,
// reproduction_cost.hpp).
TEST_F(CompareCommand, TheBudgetCountsTheFringeColumn) {
  const testing::CliResult off = run("compare --quick --seeds 1 --max-physics-steps 1");
  const testing::CliResult on = run("compare --quick --fringes --seeds 1 --max-physics-steps 1");
  EXPECT_EQ(off.status, 2);
  EXPECT_EQ(on.status, 2);
  EXPECT_NE(off.err.find("(5.02e+03 s of simulated time"), std::string::npos) << off.err;
  EXPECT_NE(on.err.find("(6.68e+03 s of simulated time"), std::string::npos) << on.err;
}

// compare --lock (issue 29): the hold's length is checked before anything runs, named, and only
// with --lock; the budget counts four holds a seed of 1.75 s (the measurements before the hold)
// plus the hold: 5016 + 4 x 61.75 s with the default minute, 5016 + 4 x 6.75 s with 5 s.
TEST_F(CompareCommand, TheLockHoldIsCheckedAndCountedInTheBudget) {
  for (const char* bad : {"0", "-1", "3601", "nan", "x"}) {
    const testing::CliResult r =
        run(std::string("compare --quick --seeds 1 --lock --lock-hold-s ") + bad);
    EXPECT_EQ(r.status, 2) << bad;
    EXPECT_NE(r.err.find("--lock-hold-s"), std::string::npos) << bad << ": " << r.err;
  }
  const testing::CliResult alone = run("compare --quick --seeds 1 --lock-hold-s 5");
  EXPECT_EQ(alone.status, 2);
  EXPECT_NE(alone.err.find("--lock"), std::string::npos) << alone.err;
  const testing::CliResult minute = run("compare --quick --lock --seeds 1 --max-physics-steps 1");
  const testing::CliResult five =
      run("compare --quick --lock --lock-hold-s 5 --seeds 1 --max-physics-steps 1");
  EXPECT_EQ(minute.status, 2);
  EXPECT_EQ(five.status, 2);
  EXPECT_NE(minute.err.find("(5.26e+03 s of simulated time"), std::string::npos) << minute.err;
  EXPECT_NE(five.err.find("(5.04e+03 s of simulated time"), std::string::npos) << five.err;
}

// Issue 31: configs/plants/, twins not used in development. A quick compare on each exits 0:
// every figure of every controller valid, except that the paper's 10 kHz figures may be not
// applicable, and then only with compare's ring test's reason (docs/compare.md). Not yet
// contact-spread: its oracle holds only at 0.17 x the paper's gains, too slow for the
// supervisor's tracking rule on its 10 and 11 um moves (docs/compare.md, what is left).
class ComparePlants : public testing::CliTest, public ::testing::WithParamInterface<const char*> {};

TEST_P(ComparePlants, QuickRunIsValid) {
  const std::string cfg = testing::source_dir() + "/configs/plants/" + GetParam() + ".toml";
  const testing::CliResult r = run("compare --quick --seeds 1 --json --config '" + cfg + "'");
  EXPECT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["valid"].get<bool>());
  EXPECT_TRUE(j["invalid_reasons"].empty()) << j["invalid_reasons"];
  ASSERT_EQ(j["per_seed"].size(), 1U);
  for (const nlohmann::json* o : {&j, &j["per_seed"][0]}) {
    for (const char* v : {"paper", "improved", "oracle"}) {
      EXPECT_TRUE((*o)[std::string(v) + "_not_valid"].empty())
          << v << ": " << (*o)[std::string(v) + "_not_valid"];
      for (const auto& [key, why] : (*o)[std::string(v) + "_not_applicable"].items()) {
        EXPECT_EQ(std::string(v), "paper") << key;
        EXPECT_NE(key.find("10kHz"), std::string::npos) << key;
        EXPECT_NE(why.get<std::string>().find("re-expressed at 10 kHz are unstable on this plant"),
                  std::string::npos)
            << key << ": " << why;
        EXPECT_TRUE((*o)["paper_" + key].is_null()) << key;
      }
    }
  }
  // The oracle ran its experiments: it reached the travel of the others (0 before, issue 31).
  EXPECT_GT(j["oracle_travel_semi_closed_um"].get<double>(), 10.0);
  EXPECT_GE(j["per_seed"][0]["oracle_holding_gains_scale"].get<double>(), 0.05);
}

INSTANTIATE_TEST_SUITE_P(Issue31, ComparePlants,
                         ::testing::Values("thick-plate", "payload", "soft-hysteresis"),
                         [](const auto& param_info) {
                           std::string name = param_info.param;
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });

}  // namespace
}  // namespace piezoshift
