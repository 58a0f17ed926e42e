// `piezoshift calibrate` and `piezoshift reproduce` as a user runs them.
#include <nlohmann/json.hpp>

#include "../support/cli_test.hpp"

namespace piezoshift {
namespace {

using ReproduceCommand = testing::CliTest;

TEST_F(ReproduceCommand, QuickRunWritesTheReportAndPrintsTheSummary) {
  const std::string out = path("report");
  const testing::CliResult r = run("reproduce --quick --seed 2 --json --out '" + out + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j["travel_open_loop_um"].get<double>(), 12.9, 0.3);
  EXPECT_LT(j["step_settling_time_s"].get<double>(), 0.3);
  EXPECT_EQ(j["seed"], 2);
  EXPECT_EQ(j["schedule"], "quick");
  EXPECT_TRUE(std::filesystem::exists(out + "/report.md"));
  EXPECT_TRUE(std::filesystem::exists(out + "/summary.json"));
  // The CSVs are what `analyze` reads: the same metric comes back from the recorded data.
  const testing::CliResult a =
      run("analyze repeatability --json --data '" + out + "/repeatability_5um.csv'");
  ASSERT_EQ(a.status, 0) << a.err;
  EXPECT_NEAR(nlohmann::json::parse(a.out)["repeatability_nm"].get<double>(),
              j["repeatability_5um_nm"].get<double>(), 1e-3);
  // The report's measurement is `measure`'s: the calibration it wrote and the measurement's seed
  // (seed + 100) take it again, number for number (issue 28).
  ASSERT_TRUE(j["measurement_valid"].get<bool>());
  EXPECT_EQ(j["measurement_seed"], 102);
  const testing::CliResult m =
      run("measure --camera twin --free-run --seed 102 --json "
          "--calibration '" +
          out + "/calibration.toml' --out '" + path("measurement") + "'");
  ASSERT_EQ(m.status, 0) << m.err;
  const auto mj = nlohmann::json::parse(m.out);
  EXPECT_EQ(mj["error_rms_nm"].get<double>(), j["measurement_error_rms_nm"].get<double>());
  EXPECT_EQ(mj["surface_rms_nm"].get<double>(), j["measurement_surface_rms_nm"].get<double>());
  EXPECT_EQ(mj["recovered_steps_rad"][0], j["measurement_recovered_steps_rad"]);
  EXPECT_LT(j["measurement_error_rms_nm"].get<double>(), 1.0);
}

TEST_F(ReproduceCommand, CalibrateWritesAFileThatRunLoads) {
  const std::string cal = path("cal.toml");
  const testing::CliResult c = run("calibrate --pid paper --json --out '" + cal + "'");
  ASSERT_EQ(c.status, 0) << c.err;
  const auto j = nlohmann::json::parse(c.out);
  EXPECT_DOUBLE_EQ(j["pid_gains"]["kp"].get<double>(), 0.6);
  EXPECT_NEAR(j["A"][0][0].get<double>(), -0.4218, 0.05);  // the twin is built on the paper's A
  EXPECT_EQ(j["p"].size(), 4U);
  const testing::CliResult r =
      run("run --daq sim --calibration '" + cal + "' --step-um 5 --duration-s 0.2 --json");
  EXPECT_EQ(r.status, 0) << r.err;
}

// A plant the procedure cannot calibrate is a failure with its reason and exit status 4, never a
// report of plausible numbers: one stack with 70 % of its stroke saturates in stage 2.
TEST_F(ReproduceCommand, APlantThatCannotBeCalibratedIsAFailureWithItsReason) {
  const std::string cfg = write("short.toml", "[twin.piezo]\nfree_stroke_scale = [1, 0.7, 1]\n");
  const testing::CliResult r =
      run("reproduce --quick --json --config '" + cfg + "' --out '" + path("o") + "'");
  EXPECT_EQ(r.status, 4) << r.err;
  EXPECT_NE(r.err.find("not valid: calibration stage 2"), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find("travel_open_loop_um"), std::string::npos) << r.out;
  const testing::CliResult c =
      run("calibrate --config '" + cfg + "' --out '" + path("c.toml") + "'");
  EXPECT_EQ(c.status, 4) << c.err;
  EXPECT_FALSE(std::filesystem::exists(path("c.toml")));
}

// Without a calibration file, `run --daq sim` calibrates the twin first, so the paper's 11 um
// step (Figure 10) runs without a fault; a step beyond the measured travel is refused up front.
TEST_F(ReproduceCommand, RunOnTheTwinWithoutACalibrationMakesThePapersStep) {
  testing::CliResult r = run("run --daq sim --free-run --step-um 11 --duration-s 1 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(nlohmann::json::parse(r.out)["fault_detected"].get<bool>());
  EXPECT_NE(r.err.find("calibrating the twin first"), std::string::npos) << r.err;
  r = run("run --daq sim --free-run --step-um 12 --duration-s 1");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("beyond the calibrated semi-closed-loop travel"), std::string::npos)
      << r.err;
}

// Issue 30: calibrate and reproduce run their benches under the installation's [safety], as
// `run` does. Outputs held to 4 V cannot reach stage 2's 7 um poses: the supervisor trips
// (saturation) and both fail naming it; the same section at its default values calibrates.
TEST_F(ReproduceCommand, CalibrateAndReproduceRunUnderTheInstallationsSafety) {
  const std::string tight = write("tight.toml", "[safety]\noutput_max_V = 4\n");
  const testing::CliResult c =
      run("calibrate --config '" + tight + "' --out '" + path("tight.toml.out") + "'");
  EXPECT_EQ(c.status, 4) << c.err;
  EXPECT_NE(c.err.find("the safety supervisor tripped (saturation"), std::string::npos) << c.err;
  EXPECT_FALSE(std::filesystem::exists(path("tight.toml.out")));
  const testing::CliResult r =
      run("reproduce --quick --json --config '" + tight + "' --out '" + path("o") + "'");
  EXPECT_EQ(r.status, 4) << r.err;
  EXPECT_NE(r.err.find("the safety supervisor tripped (saturation"), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find("travel_open_loop_um"), std::string::npos) << r.out;

  const std::string defaults = write("defaults.toml", "[safety]\noutput_max_V = 10\n");
  const testing::CliResult d =
      run("calibrate --json --config '" + defaults + "' --out '" + path("cal.toml") + "'");
  ASSERT_EQ(d.status, 0) << d.err;
  EXPECT_DOUBLE_EQ(nlohmann::json::parse(d.out)["pid_gains"]["kp"].get<double>(), 0.6);
}

TEST_F(ReproduceCommand, BadInputExitsWithStatusTwo) {
  const std::string bad = write("bad.toml", "[twin.piezo]\nfree_stroke_scale = [1, -1, 1]\n");
  testing::CliResult r = run("reproduce --quick --config '" + bad + "' --out '" + path("o") + "'");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("bad.toml"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("free_stroke_scale"), std::string::npos) << r.err;
  r = run("reproduce --pid sometimes");
  EXPECT_EQ(r.status, 2);
  r = run("calibrate --out '" + path("no/such/dir/cal.toml") + "' --pid paper");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("cal.toml"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace piezoshift
