// Runs `piezoshift simulate` and checks its output, its log and its exit status.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../support/cli_test.hpp"

namespace {

using RunResult = piezoshift::testing::CliResult;
class SimulateCommand : public piezoshift::testing::CliTest {
 protected:
  RunResult run(const std::string& args) const { return CliTest::run("simulate " + args); }
};

TEST_F(SimulateCommand, OpenLoopAtTenVoltsReachesThePapersTravel) {
  const RunResult r = run("--open-loop-volts 10,10,10 --duration-s 1.5 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["mode"], "open_loop");
  EXPECT_NEAR(j["final_plate_z_um"].get<double>(), 12.93, 0.05);
  ASSERT_EQ(j["final_points_um"].size(), 3u);
  double mean = 0.0;
  for (const auto& p : j["final_points_um"])
    mean += p.get<double>() / 3.0;
  EXPECT_NEAR(mean, 12.93, 0.05);  // the points differ: the legs' strokes do (docs/twin.md)
}

TEST_F(SimulateCommand, StepWithThePapersControllerLogsEveryTickWithUnits) {
  const std::string log = path("step.csv");
  const RunResult r = run("--step-um 5 --duration-s 0.5 --seed 3 --json --log '" + log + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["mode"], "step");
  EXPECT_EQ(j["ticks"], 500);
  // As `run`: without --calibration the twin is calibrated first by the paper's procedure, so
  // the points reach Z_d = 5 um but for the twin's noise and what creep is left after 0.5 s
  // (measured 4.9955 to 5.0028 um). Simulate once ran the paper's own A and p here and
  // ended 0.31 um high (the test below keeps that case).
  EXPECT_NE(j["calibration"].get<std::string>().find("the twin's own calibration"),
            std::string::npos);
  for (const auto& p : j["final_true_points_um"])
    EXPECT_NEAR(p.get<double>(), 5.0, 0.02);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(j["final_zd_um"][i], 5.0);
    EXPECT_DOUBLE_EQ(j["final_error_um"][i].get<double>(),
                     j["final_points_um"][i].get<double>() - 5.0);
  }
  std::ifstream in(log);
  std::string line, header;
  int rows = 0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#')
      continue;
    if (header.empty())
      header = line;
    else
      ++rows;
  }
  EXPECT_EQ(rows, 500);
  EXPECT_EQ(header.rfind("t_s,zd1_um,zd2_um,zd3_um,s1_um", 0), 0u) << header;
  EXPECT_NE(header.find("plate_z_um"), std::string::npos);
  EXPECT_NE(header.find(",truth3_um,interferometer1_um,"), std::string::npos);
}

// The paper's own controller (Section 4's gains, A and p, fitted to its stage, not the twin):
// the points go to p(5) = 5.3585 um less two bows that a cubic fitted on the twin removes but the
// paper's p does not: the conditioner's (~14 nm at 2.9 V) and the Hertz contact's (the stack
// elongates ~38 nm more than the secant the gauge gains assume, so the gauge reaches its target
// with the leg short); measured 5.309 to 5.311 um.
TEST_F(SimulateCommand, ThePapersOwnCalibrationFileLeavesTheTwinsBowsInPlace) {
  const std::string cal = write("paper.toml",
                                "[controller]\nkp = 0.6\nki = 0.2\nkd = 0.001\n"
                                "p = [-0.0001009, 0.000389, 1.014, 0.2914]\n"
                                "A = [[-0.4218, 0.6030, 0.6547], [0.3482, -0.1491, 0.6962], "
                                "[0.6321, 0.4397, -0.2980]]\n");
  const RunResult r =
      run("--step-um 5 --duration-s 0.5 --seed 3 --json --calibration '" + cal + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["calibration"], cal);
  for (const auto& p : j["final_true_points_um"])
    EXPECT_NEAR(p.get<double>(), 5.3585 - 0.050, 0.03);
  // Open loop runs no controller: a calibration there is refused, not ignored.
  const RunResult open = run("--open-loop-volts 1,1,1 --calibration '" + cal + "'");
  EXPECT_EQ(open.status, 2);
  EXPECT_NE(open.err.find("--calibration: open loop"), std::string::npos) << open.err;
}

TEST_F(SimulateCommand, SameSeedGivesTheSameLogAndAnotherSeedDoesNot) {
  const std::string a = path("a.csv"), b = path("b.csv"), c = path("c.csv");
  ASSERT_EQ(run("--step-um 8 --duration-s 0.3 --seed 9 --log '" + a + "'").status, 0);
  ASSERT_EQ(run("--step-um 8 --duration-s 0.3 --seed 9 --log '" + b + "'").status, 0);
  ASSERT_EQ(run("--step-um 8 --duration-s 0.3 --seed 10 --log '" + c + "'").status, 0);
  EXPECT_EQ(read_text(a), read_text(b));
  EXPECT_NE(read_text(a), read_text(c));
}

TEST_F(SimulateCommand, ProfileIsFollowedAsRunFollowsIt) {
  const std::string profile = write("p.csv", "t_s,zd_um\n0.0,2.0\n0.3,6.0\n");
  const RunResult r = run("--profile '" + profile + "' --duration-s 0.6 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["mode"], "profile");
  // The twin calibrated first: the points end on Z_d = 6 um (measured 6.0014 to 6.0118 um, 0.3 s
  // after the ramp ended).
  for (const auto& p : j["final_true_points_um"])
    EXPECT_NEAR(p.get<double>(), 6.0, 0.03);
}

TEST_F(SimulateCommand, BadInputExitsTwoWithAClearMessage) {
  RunResult r = run("--open-loop-volts 10,12,10 --duration-s 0.1");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--open-loop-volts"), std::string::npos) << r.err;
  // Below the supervisor's 0 V the bench would clamp: refused, never clamped in silence.
  r = run("--open-loop-volts 5,-1,5 --duration-s 0.1");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("V2 = -1"), std::string::npos) << r.err;
  r = run("--step-um 5 --duration-s -1");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--duration-s"), std::string::npos) << r.err;
  r = run("--step-um 5 --open-loop-volts 1,1,1");
  EXPECT_EQ(r.status, 2);
  r = run("--duration-s 1");
  EXPECT_EQ(r.status, 2);
  const std::string bad = write("bad.toml", "[twin.amplifier]\naverage_power_W = 0\n");
  r = run("--step-um 5 --config '" + bad + "'");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("twin.amplifier.average_power_W"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(bad), std::string::npos) << r.err;
  const std::string profile = write("p.csv", "t_s,zd_um\n0.5,2.0\n0.2,6.0\n");
  r = run("--profile '" + profile + "' --duration-s 0.1");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("p.csv:3"), std::string::npos) << r.err;
}

// A simulation's cost is estimated before it starts and refused above the budget unless
// the budget is raised explicitly; values beyond the twin's ranges name the file, line and key.
TEST_F(SimulateCommand, CostIsEstimatedAndRefusedAboveTheBudgetUnlessRaised) {
  RunResult r = run("--step-um 5 --duration-s 1e308");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--duration-s 1e+308"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("more than 1e+308 physics steps"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("budget of 1e+09"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--max-physics-steps"), std::string::npos) << r.err;
  // 1 MHz physics: 1000 steps per 1 ms tick, 0.05 s is 5e4 steps: under the default budget,
  // above a budget of 1e4.
  const std::string fast = write("fast.toml", "[twin]\nphysics_rate_Hz = 1e6\n");
  r = run("--open-loop-volts 1,1,1 --duration-s 0.05 --config '" + fast + "'");
  EXPECT_EQ(r.status, 0) << r.err;
  r = run("--open-loop-volts 1,1,1 --duration-s 0.05 --max-physics-steps 1e4 --config '" + fast +
          "'");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("5e+04 physics steps"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(fast), std::string::npos) << r.err;
  r = run("--step-um 5 --max-physics-steps 0");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--max-physics-steps = 0 must be in [1, 1e15]"), std::string::npos) << r.err;
}

// The installation's [safety] is the supervisor's: 9 V passes the built-in 10 V limit, not 8 V.
TEST_F(SimulateCommand, SafetySectionOfTheConfigIsTheSupervisors) {
  const std::string site = write("site.toml", "[safety]\noutput_max_V = 8.0\n");
  EXPECT_EQ(run("--open-loop-volts 9,9,9 --duration-s 0.01").status, 0);
  const RunResult r = run("--open-loop-volts 9,9,9 --duration-s 0.01 --config '" + site + "'");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("V1 = 9 is outside the supervisor's 0 to 8 V"), std::string::npos) << r.err;
}

TEST_F(SimulateCommand, ConfigValuesThatUsedToExhaustOrHangAreRefusedByFileAndKey) {
  const struct {
    const char* toml;
    const char* key;
  } cases[] = {{"[twin]\nphysics_rate_Hz = 2e12\n", "twin.physics_rate_Hz"},
               {"[twin]\nphysics_rate_Hz = 2e10\n", "twin.physics_rate_Hz"},
               {"[twin.daq]\nsample_time_s = 1e6\n", "twin.daq.sample_time_s"},
               {"[twin.amplifier]\noutput_max_V = 5e-324\n", "twin.amplifier.output_max_V"}};
  for (const auto& c : cases) {
    const std::string cfg = write("c.toml", c.toml);
    const RunResult r = run("--step-um 5 --duration-s 0.05 --config '" + cfg + "'");
    EXPECT_EQ(r.status, 2) << c.toml;
    EXPECT_NE(r.err.find(cfg + ":2:"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(c.key), std::string::npos) << r.err;
  }
}

}  // namespace
