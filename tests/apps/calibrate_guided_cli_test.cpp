// Runs the guided `piezoshift calibrate --daq sim --interferometer ...`: the readings the twin's
// interferometer gives (recorded in the session file of a first run) are typed back through the
// prompt and read from a log file, and must give the A and p of `calibrate` on the twin; a wrong
// reading is refused and asked again; a run whose input ends resumes where it stopped.
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
using piezoshift::testing::max_difference;

class GuidedCalibrateCli : public piezoshift::testing::CliTest {
 protected:
  // The twin's interferometer readings of a guided run (one per step taken; skipped steps have
  // none), and that run's fit.
  void SetUp() override {
    CliTest::SetUp();
    std::filesystem::create_directories(path("sim"));
    const CliResult r = run("calibrate --daq sim --interferometer sim --seed 3 --json --out '" +
                            path("sim/cal.toml") + "'");
    ASSERT_EQ(r.status, 0) << r.err;
    sim_fit_ = fit_of(r.out);
    session_ = nlohmann::json::parse(read_text(path("sim/cal.session.json")));
    for (const auto& e : session_.at("readings"))
      if (!e.at("reading_um").is_null())
        readings_.push_back(e.at("reading_um").get<double>());
  }

  std::string lines(std::size_t from, std::size_t to) const {
    std::string s;
    for (std::size_t i = from; i < to && i < readings_.size(); ++i)
      s += fmt::format("{:.17g}\n", readings_[i]);
    return s;
  }

  CliResult prompt(const std::string& out, const std::string& input_file) {
    std::filesystem::create_directories(std::filesystem::path(out).parent_path());
    return run("calibrate --daq sim --interferometer prompt --seed 3 --json --out '" + out +
               "' < '" + input_file + "'");
  }

  Fit sim_fit_;
  nlohmann::json session_;
  std::vector<double> readings_;
};

TEST_F(GuidedCalibrateCli, PromptedTwinReadingsGiveTheTwinCalibrationsAAndP) {
  // 3 points x 3 repeats x 3 actuators x 2 poses, then 12 commands of which the twin's 0 um is
  // left out (a PID at its limit, as in `calibrate`).
  EXPECT_EQ(session_.at("steps").get<int>(), 66);
  ASSERT_EQ(readings_.size(), 65u);
  const CliResult twin = run("calibrate --seed 3 --json --out '" + path("twin.toml") + "'");
  ASSERT_EQ(twin.status, 0) << twin.err;
  const Fit twin_fit = fit_of(twin.out);

  const CliResult r = prompt(path("prompt/cal.toml"), write("in.txt", lines(0, 65)));
  ASSERT_EQ(r.status, 0) << r.err;
  const Fit prompted = fit_of(r.out);
  // The same readings and the same deterministic twin: the same numbers.
  EXPECT_LT(max_difference(prompted, sim_fit_), 1e-12);
  // The guided order (per point) against `calibrate`'s (all points at once).
  EXPECT_LT(max_difference(prompted, twin_fit), 0.002);
  EXPECT_NE(r.err.find("reading 1 of 66"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("put the interferometer's optics on measurement point P2"),
            std::string::npos);
  // The file `run` loads.
  EXPECT_NE(read_text(path("prompt/cal.toml")).find("A = [["), std::string::npos);
}

TEST_F(GuidedCalibrateCli, AnImplausibleReadingIsRefusedAndAskedAgain) {
  // Reading 2 (actuator 1 moved, at P1) typed as a move of the wrong sign, then in nm, then
  // "abc", then right; reading 3 (the next base) 0.2 um off the first base (drift), then right.
  std::string in = lines(0, 1);
  in += fmt::format("{:.17g}\n{:.17g}\nabc\n", 2.0 * readings_[0] - readings_[1],
                    1000.0 * readings_[1]);
  in += lines(1, 2);
  in += fmt::format("{:.17g}\n", readings_[2] + 0.2);
  in += lines(2, 65);
  const CliResult r = prompt(path("p/cal.toml"), write("in.txt", in));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_LT(max_difference(fit_of(r.out), sim_fit_), 1e-12);
  EXPECT_NE(r.err.find("refused: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("check the sign, the unit (um)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("'abc' is not a displacement in um"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("at most 0.05 um of drift"), std::string::npos) << r.err;
  // Reading 2 was asked four times, reading 3 twice.
  std::size_t n2 = 0, n3 = 0;
  for (std::size_t at = 0; (at = r.err.find("reading 2 of 66", at)) != std::string::npos; ++at)
    ++n2;
  for (std::size_t at = 0; (at = r.err.find("reading 3 of 66", at)) != std::string::npos; ++at)
    ++n3;
  EXPECT_EQ(n2, 4u);
  EXPECT_EQ(n3, 2u);
}

TEST_F(GuidedCalibrateCli, AnInterruptedSessionResumesWhereItStopped) {
  // Input ends after 11 readings: the 11th is a base pose whose moved reading never came, so
  // the resumed run asks for it again.
  const std::string out = path("r/cal.toml");
  const CliResult first = prompt(out, write("in1.txt", lines(0, 11)));
  EXPECT_EQ(first.status, 2);
  EXPECT_EQ(first.out, "");
  EXPECT_NE(first.err.find("standard input ended: 11 of 66 steps are recorded in"),
            std::string::npos)
      << first.err;
  EXPECT_FALSE(std::filesystem::exists(out));
  const auto recorded = nlohmann::json::parse(read_text(path("r/cal.session.json")));
  EXPECT_EQ(recorded.at("readings").size(), 11u);

  const CliResult second = prompt(out, write("in2.txt", lines(10, 65)));
  ASSERT_EQ(second.status, 0) << second.err;
  EXPECT_NE(second.err.find("resuming"), std::string::npos);
  EXPECT_NE(second.err.find("11 of 66 steps recorded"), std::string::npos) << second.err;
  EXPECT_EQ(second.err.find("reading 10 of 66"), std::string::npos);
  EXPECT_NE(second.err.find("reading 11 of 66"), std::string::npos);
  EXPECT_LT(max_difference(fit_of(second.out), sim_fit_), 1e-12);
}

TEST_F(GuidedCalibrateCli, ReadingsFromTheInterferometerLogAreMatchedByTime) {
  // The log the interferometer software would write: one row at the middle of each window, and
  // rows between the windows that the matching must leave out.
  std::string log = "t_s,displacement_um\n";
  double last_end = 0.0;
  for (const auto& e : session_.at("readings")) {
    const double t0 = e.at("window_start_s").get<double>();
    const double t1 = e.at("window_end_s").get<double>();
    log += fmt::format("{:.17g},{}\n", 0.5 * (last_end + t0 - 0.2), 999.0);
    if (!e.at("reading_um").is_null())
      log += fmt::format("{:.17g},{:.17g}\n", 0.5 * (t0 + t1), e.at("reading_um").get<double>());
    last_end = t1;
  }
  log += fmt::format("{:.17g},0\n", last_end + 10.0);
  const std::string f = write("xl80.csv", log);
  std::filesystem::create_directories(path("f"));
  const CliResult r = run("calibrate --daq sim --interferometer 'file:" + f +
                          "' --seed 3 --json --out '" + path("f/cal.toml") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_LT(max_difference(fit_of(r.out), sim_fit_), 1e-12);
}

TEST_F(GuidedCalibrateCli, BadOptionsExitTwoNamingTheOption) {
  const CliResult a =
      run("calibrate --daq sim --interferometer laser --out '" + path("a.toml") + "'");
  EXPECT_EQ(a.status, 2);
  EXPECT_NE(a.err.find("--interferometer laser"), std::string::npos) << a.err;
  const CliResult b = run("calibrate --interferometer sim --out '" + path("b.toml") + "'");
  EXPECT_EQ(b.status, 2);
  EXPECT_NE(b.err.find("--interferometer sim needs --daq"), std::string::npos) << b.err;
  const CliResult c = run("calibrate --daq sim --interferometer 'file:" + path("none.csv") +
                          "' --out '" + path("c.toml") + "'");
  EXPECT_EQ(c.status, 2);
  EXPECT_NE(c.err.find("none.csv"), std::string::npos) << c.err;
  // A log that stops before the first window ends: refused naming the file and the window.
  const std::string shortlog = write("short.csv", "t_s,displacement_um\n0.5,0.001\n");
  const CliResult d = run("calibrate --daq sim --interferometer 'file:" + shortlog + "' --out '" +
                          path("d.toml") + "'");
  EXPECT_EQ(d.status, 2);
  EXPECT_NE(
      d.err.find("short.csv: the log ends at t_s 0.500, before the end of the window 2.000 s"),
      std::string::npos)
      << d.err;
}

TEST_F(GuidedCalibrateCli, ASessionOfOtherOptionsOrMalformedIsRefusedNamingIt) {
  // The first run's session is for seed 3: another seed does not resume it.
  const std::string out = path("sim/cal.toml");
  const CliResult other =
      run("calibrate --daq sim --interferometer sim --seed 4 --out '" + out + "'");
  EXPECT_EQ(other.status, 2);
  EXPECT_NE(other.err.find("cal.session.json: this session was recorded for"), std::string::npos)
      << other.err;
  EXPECT_NE(other.err.find("--restart"), std::string::npos);
  // --restart discards it: seed 4 gives other readings than seed 3.
  const CliResult restarted =
      run("calibrate --daq sim --interferometer sim --seed 4 --restart --json --out '" + out + "'");
  ASSERT_EQ(restarted.status, 0) << restarted.err;
  EXPECT_GT(max_difference(fit_of(restarted.out), sim_fit_), 1e-6);

  std::filesystem::create_directories(path("m"));
  write("m/cal.session.json", "{\"format\": \"piezoshift guided calibration session 1\", \"pl");
  const CliResult bad =
      run("calibrate --daq sim --interferometer sim --seed 3 --out '" + path("m/cal.toml") + "'");
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("m/cal.session.json: not a session file"), std::string::npos) << bad.err;
  const CliResult search =
      run("calibrate --daq sim --interferometer sim --pid search --out '" + path("s.toml") + "'");
  EXPECT_EQ(search.status, 2);
  EXPECT_NE(search.err.find("--pid search"), std::string::npos) << search.err;
}

}  // namespace
