// Runs the guided calibration through the real-time loop (rig/loop_rig.hpp) on the twin,
// paced by the procedure (`calibrate --daq sim-rt --free-run`): the loop in its own thread, the
// procedure talking to it only through the host link. Its A and p must be those of `calibrate`
// on the twin within 0.002; the twin's readings typed back at the prompt and read
// from a log matched by time give the same numbers again (the paced loop is deterministic).
// Hardware (`--daq comedi:...`) is refused with exit 2 when the device cannot be opened.
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../support/calibration_fit.hpp"
#include "../support/cli_test.hpp"

namespace {

using piezoshift::testing::CliResult;

using piezoshift::testing::Fit;
using piezoshift::testing::fit_of;
using piezoshift::testing::fit_of_p;
using piezoshift::testing::max_difference;

class LoopRigCli : public piezoshift::testing::CliTest {
 protected:
  void SetUp() override {
    CliTest::SetUp();
    std::filesystem::create_directories(path("loop"));
    const CliResult r =
        run("calibrate --daq sim-rt --free-run --interferometer sim --seed 3 --json --out '" +
            path("loop/cal.toml") + "'");
    ASSERT_EQ(r.status, 0) << r.err;
    loop_fit_ = fit_of(r.out);
    session_ = nlohmann::json::parse(read_text(path("loop/cal.session.json")));
    for (const auto& e : session_.at("readings"))
      if (!e.at("reading_um").is_null())
        readings_.push_back(e.at("reading_um").get<double>());
  }

  Fit loop_fit_;
  nlohmann::json session_;
  std::vector<double> readings_;
};

TEST_F(LoopRigCli, TheLoopRigGivesTheTwinCalibrationsAAndP) {
  // The same plan as on the simulated clock: 54 poses of stage 2, 12 commands of stage 3 of
  // which 0 um is left out (a PID at its output limit).
  EXPECT_EQ(session_.at("steps").get<int>(), 66);
  ASSERT_EQ(readings_.size(), 65u);
  const CliResult twin = run("calibrate --seed 3 --json --out '" + path("twin.toml") + "'");
  ASSERT_EQ(twin.status, 0) << twin.err;
  // Stage 3 runs on the same twin after stage 2 (one stage, as on hardware), where `calibrate`
  // uses a fresh twin of another seed: the difference is the twin's repeatability, ~0.001.
  EXPECT_LT(max_difference(loop_fit_, fit_of(twin.out)), 0.002);
  const CliResult guided = run("calibrate --daq sim --interferometer sim --seed 3 --json --out '" +
                               path("guided.toml") + "'");
  ASSERT_EQ(guided.status, 0) << guided.err;
  EXPECT_LT(max_difference(loop_fit_, fit_of(guided.out)), 0.002);
  // Windows: one averaging window (1 s of ticks) each, on the loop's clock, in order, and the
  // stage-2 base pose holds the SGS targets at 2 um.
  double last_end = -1.0;
  for (const auto& e : session_.at("readings")) {
    const double t0 = e.at("window_start_s").get<double>();
    const double t1 = e.at("window_end_s").get<double>();
    EXPECT_NEAR(t1 - t0, 1.0, 1e-9);
    EXPECT_GE(t0, last_end);
    last_end = t1;
  }
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(session_.at("readings").at(0).at("sgs_um").at(i).get<double>(), 2.0, 0.01);
  // The fits' data beside the calibration file: `fit` gets the same A and p from it.
  const CliResult m = run("fit matrix --json --data '" + path("loop/matrix_poses.csv") + "'");
  ASSERT_EQ(m.status, 0) << m.err;
  const CliResult p = run("fit poly --json --data '" + path("loop/polynomial_points.csv") + "'");
  ASSERT_EQ(p.status, 0) << p.err;
  EXPECT_EQ(nlohmann::json::parse(m.out).at("poses").get<int>(), 9);
  Fit refit = fit_of_p(p.out);
  const auto a = nlohmann::json::parse(m.out).at("A");
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      refit.a[r][c] = a.at(r).at(c).get<double>();
  EXPECT_LT(max_difference(refit, loop_fit_), 1e-7);
}

TEST_F(LoopRigCli, PromptedAndLoggedReadingsThroughTheLoopGiveTheSameNumbers) {
  std::string in;
  for (double v : readings_)
    in += fmt::format("{:.17g}\n", v);
  std::filesystem::create_directories(path("prompt"));
  const CliResult r =
      run("calibrate --daq sim-rt --free-run --interferometer prompt --seed 3 --json --out '" +
          path("prompt/cal.toml") + "' < '" + write("in.txt", in) + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_LT(max_difference(fit_of(r.out), loop_fit_), 1e-12);
  EXPECT_NE(r.err.find("reading 66 of 66"), std::string::npos) << r.err;

  std::string log = "t_s,displacement_um\n";
  for (const auto& e : session_.at("readings"))
    if (!e.at("reading_um").is_null())
      log += fmt::format(
          "{:.17g},{:.17g}\n",
          0.5 * (e.at("window_start_s").get<double>() + e.at("window_end_s").get<double>()),
          e.at("reading_um").get<double>());
  log += fmt::format("{:.17g},0\n",
                     session_.at("readings").back().at("window_end_s").get<double>() + 10.0);
  std::filesystem::create_directories(path("file"));
  const CliResult f =
      run("calibrate --daq sim-rt --free-run --interferometer 'file:" + write("xl80.csv", log) +
          "' --seed 3 --json --out '" + path("file/cal.toml") + "'");
  ASSERT_EQ(f.status, 0) << f.err;
  EXPECT_LT(max_difference(fit_of(f.out), loop_fit_), 1e-12);
}

TEST_F(LoopRigCli, AnInterruptedLoopSessionResumesFromTheNextStep) {
  // Hardware does not replay: the resumed run drives only the steps not yet recorded.
  std::string first, second;
  for (std::size_t i = 0; i < readings_.size(); ++i)
    (i < 20 ? first : second) += fmt::format("{:.17g}\n", readings_[i]);
  const std::string out = path("r/cal.toml");
  std::filesystem::create_directories(path("r"));
  const std::string cmd =
      "calibrate --daq sim-rt --free-run --interferometer prompt --seed 3 --json --out '" + out +
      "' < '";
  const CliResult a = run(cmd + write("in1.txt", first) + "'");
  EXPECT_EQ(a.status, 2);
  EXPECT_NE(a.err.find("20 of 66 steps are recorded"), std::string::npos) << a.err;
  const CliResult b = run(cmd + write("in2.txt", second) + "'");
  ASSERT_EQ(b.status, 0) << b.err;
  EXPECT_NE(b.err.find("20 of 66 steps recorded"), std::string::npos) << b.err;
  EXPECT_EQ(b.err.find("reading 20 of 66"), std::string::npos);
  // The twin moved on in between (a fresh loop, no replay): not the same numbers, the same
  // calibration within the twin's repeatability.
  EXPECT_LT(max_difference(fit_of(b.out), loop_fit_), 0.002);
}

class LoopRigOptionsCli : public piezoshift::testing::CliTest {};

TEST_F(LoopRigOptionsCli, HardwareAndItsOptionsAreCheckedBeforeAnythingMoves) {
  const CliResult a =
      run("calibrate --daq comedi:/dev/piezoshift-no-such-board --interferometer "
          "prompt --out '" +
          path("a.toml") + "' < /dev/null");
  EXPECT_EQ(a.status, 2);
  EXPECT_NE(a.err.find("/dev/piezoshift-no-such-board"), std::string::npos) << a.err;
  const CliResult b = run("calibrate --daq comedi:/dev/comedi0 --interferometer sim --out '" +
                          path("b.toml") + "'");
  EXPECT_EQ(b.status, 2);
  EXPECT_NE(b.err.find("--interferometer sim: the twin's interferometer does not see the stage"),
            std::string::npos)
      << b.err;
  const CliResult c =
      run("calibrate --daq sim --free-run --interferometer sim --out '" + path("c.toml") + "'");
  EXPECT_EQ(c.status, 2);
  EXPECT_NE(c.err.find("--free-run needs --daq sim-rt"), std::string::npos) << c.err;
  const CliResult d =
      run("calibrate --daq sim-loop --interferometer sim --out '" + path("d.toml") + "'");
  EXPECT_EQ(d.status, 2);
  EXPECT_NE(d.err.find("expected sim, sim-rt or comedi:/dev/comediN"), std::string::npos) << d.err;
}

}  // namespace
