// The files one command writes are the files the next reads (docs/files.md): `fit ... --out`
// into the calibration `run` loads, `run`'s and `simulate`'s logs into `analyze --column`, one
// profile for `run` and `simulate`, `run --config`, and `run`'s final position in its summary.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../support/cli_test.hpp"
#include "piezoshift/calibration/calibration_file.hpp"
#include "piezoshift/control/cubic_polynomial.hpp"
#include "piezoshift/control/transmission_matrix.hpp"
#include "piezoshift/io/csv_table.hpp"
#include "piezoshift/io/csv_writer.hpp"

namespace {

using piezoshift::testing::CliResult;

const piezoshift::control::Mat3 kPaperA = piezoshift::control::TransmissionMatrix{}.a;
const piezoshift::control::CubicPolynomial kPaperP;

class ConnectedFilesCli : public piezoshift::testing::CliTest {
 protected:
  // Mean of a log column over the rows with t_s in [from, to].
  static double mean_over(const std::string& file, const std::string& column, double from,
                          double to) {
    const auto t = piezoshift::io::CsvTable::load(file);
    const std::vector<double> ts = t.column("t_s");
    const std::vector<double> v = t.column(column);
    double sum = 0.0;
    int n = 0;
    for (std::size_t i = 0; i < ts.size(); ++i)
      if (ts[i] >= from && ts[i] <= to) {
        sum += v[i];
        ++n;
      }
    EXPECT_GT(n, 0);
    return sum / n;
  }
};

TEST_F(ConnectedFilesCli, FitMatrixThenPolyIntoOneFileThatRunLoads) {
  // Poses with S = A Z exactly, and points on the paper's p.
  std::string poses = "s1_um,s2_um,s3_um,z1_um,z2_um,z3_um\n";
  for (int i = 0; i < 9; ++i) {
    const double z[3] = {1.0 + (i % 3), 2.0 + 0.5 * ((i / 3) % 3), 0.5 + 1.5 * (i % 4)};
    double s[3];
    for (int r = 0; r < 3; ++r)
      s[r] = kPaperA[r][0] * z[0] + kPaperA[r][1] * z[1] + kPaperA[r][2] * z[2];
    poses += fmt::format("{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}\n", s[0], s[1], s[2],
                         z[0], z[1], z[2]);
  }
  std::string points = "command_um,measured_um\n";
  for (int k = 0; k <= 10; ++k)
    points += fmt::format("{:.17g},{}\n", kPaperP(static_cast<double>(k)), k);
  const std::string cal = path("cal.toml");
  ASSERT_EQ(run("fit matrix --data '" + write("poses.csv", poses) + "' --out '" + cal + "'").status,
            0);
  const CliResult poly =
      run("fit poly --json --data '" + write("points.csv", points) + "' --out '" + cal + "'");
  ASSERT_EQ(poly.status, 0) << poly.err;
  EXPECT_EQ(nlohmann::json::parse(poly.out).at("calibration_file"), cal);
  // Both fits in the one file: A from the first, p from the second.
  const auto params = piezoshift::calibration::load_calibration_file(cal);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(params.matrix.a[r][c], kPaperA[r][c], 1e-9) << r << c;
  EXPECT_NEAR(params.polynomial.p1, kPaperP.p1, 1e-6);
  EXPECT_NEAR(params.polynomial.p3, kPaperP.p3, 1e-8);

  const CliResult r = run("run --daq sim --free-run --calibration '" + cal +
                          "' --step-um 5 --duration-s 0.5 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  for (int i = 0; i < 3; ++i) {
    EXPECT_DOUBLE_EQ(j.at("final_setpoint_um")[i].get<double>(), 5.0);
    // The PIDs hold their targets within a few nm after 0.5 s.
    EXPECT_LT(std::fabs(j.at("final_tracking_error_um")[i].get<double>()), 0.005);
    // The paper's A and p loaded: S = A p(Z_d), and the twin (built from the paper's A) puts
    // the points near p(5) (the gauges' and the contact's bows take ~40 nm, simulate's test).
    EXPECT_NEAR(j.at("final_interferometer_um")[i].get<double>(), kPaperP(5.0) - 0.04, 0.05);
  }
  EXPECT_NEAR(j.at("final_time_s").get<double>(), 0.5, 0.0011);
}

TEST_F(ConnectedFilesCli, AnalyzeStepReadsRunsAndSimulatesOwnLogs) {
  const std::string run_log = path("run.csv");
  ASSERT_EQ(
      run("run --daq sim --free-run --step-um 5 --duration-s 0.5 --log '" + run_log + "'").status,
      0);
  const std::string sim_log = path("sim.csv");
  ASSERT_EQ(run("simulate --step-um 5 --duration-s 0.5 --log '" + sim_log + "'").status, 0);
  for (const std::string& log : {run_log, sim_log}) {
    const CliResult a = run("analyze step --json --data '" + log + "' --column interferometer1_um");
    ASSERT_EQ(a.status, 0) << log << ": " << a.err;
    const auto j = nlohmann::json::parse(a.out);
    // The step as analyze saw it is the one in the named column of the log.
    EXPECT_GT(j.at("step_um").get<double>(), 4.5) << log;
    EXPECT_NEAR(j.at("final_um").get<double>(), mean_over(log, "interferometer1_um", 0.45, 0.499),
                0.01)
        << log;
  }
  // The two commands build the same controller (the twin calibrated first) and end where the
  // other ends: simulate once ran the paper's uncalibrated A and p, 0.3 um higher.
  EXPECT_NEAR(mean_over(sim_log, "interferometer1_um", 0.45, 0.499),
              mean_over(run_log, "interferometer1_um", 0.45, 0.499), 0.002);
  const CliResult missing = run("analyze step --data '" + run_log + "' --column ifm1_um");
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.err.find("ifm1_um"), std::string::npos) << missing.err;
}

TEST_F(ConnectedFilesCli, OneProfileDrivesRunAndSimulateAlike) {
  const std::string profile = write("p.csv", "t_s,zd_um\n0,0\n0.2,4\n");
  const CliResult r = run("run --daq sim --free-run --profile '" + profile +
                          "' --duration-s 0.4 --json --log '" + path("run.csv") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_DOUBLE_EQ(nlohmann::json::parse(r.out).at("final_setpoint_um")[1].get<double>(), 4.0);
  const CliResult s =
      run("simulate --profile '" + profile + "' --duration-s 0.4 --log '" + path("sim.csv") + "'");
  ASSERT_EQ(s.status, 0) << s.err;
  // Piecewise linear in both: half way up the ramp at 0.1 s.
  EXPECT_NEAR(mean_over(path("run.csv"), "zd1_um", 0.1, 0.1), 2.0, 0.03);
  EXPECT_NEAR(mean_over(path("sim.csv"), "zd1_um", 0.1, 0.1), 2.0, 0.03);
  const std::string old = write("old.csv", "t_s,z_um\n0,1\n");
  const CliResult bad = run("simulate --profile '" + old + "' --duration-s 0.1");
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("zd1_um"), std::string::npos) << bad.err;
}

TEST_F(ConnectedFilesCli, RunReadsItsConfiguration) {
  const std::string bad = write("bad.toml", "[twin.amplifier]\naverage_power_W = 0\n");
  const CliResult r =
      run("run --daq sim --free-run --step-um 1 --duration-s 0.1 --config '" + bad + "'");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("twin.amplifier.average_power_W"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(bad), std::string::npos) << r.err;
}

}  // namespace

namespace {

// `calibrate --controller improved` writes a file `run` loads: the run holds 5 um within 20 nm
// at every point; the same file at another loop rate is refused as input (exit 2, naming it).
// The records it fitted (excitation.csv, mode_step.csv) fit again by `fit improved` into a copy
// of the file to the same controller: the CSV's 12 decimals leave the models within 1e-9 and
// the shaper's taps (the ring-down's 9 decimals) within 1e-8.
TEST_F(ConnectedFilesCli, ImprovedCalibrationRunsFitsAgainFromItsRecordsAndIsRefusedAtAnotherRate) {
  const std::string cal = path("improved.toml");
  const CliResult c = run("calibrate --controller improved --json --out '" + cal + "'");
  ASSERT_EQ(c.status, 0) << c.err;
  const auto j = nlohmann::json::parse(c.out);
  EXPECT_EQ(j["controller"], "improved");
  EXPECT_TRUE(j["shaped"].get<bool>());
  const CliResult r =
      run("run --calibration '" + cal + "' --step-um 5 --duration-s 1 --free-run --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto s = nlohmann::json::parse(r.out);
  for (const auto& z : s["final_interferometer_um"])
    EXPECT_NEAR(z.get<double>(), 5.0, 0.02);
  const CliResult bad =
      run("run --calibration '" + cal + "' --step-um 5 --duration-s 1 --free-run --rate-hz 10000");
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("improved.toml: [improved] sample_time_s"), std::string::npos) << bad.err;

  const std::string excitation = j["excitation_file"], mode = j["mode_file"];
  const std::string refit = path("refit.toml");
  std::filesystem::copy_file(cal, refit);
  const CliResult f = run("fit improved --data '" + excitation + "' --mode-data '" + mode +
                          "' --out '" + refit + "' --json");
  ASSERT_EQ(f.status, 0) << f.err;
  const auto a = piezoshift::calibration::load_calibration_file(cal).improved;
  const auto b = piezoshift::calibration::load_calibration_file(refit).improved;
  EXPECT_EQ(b.sample_time_s, a.sample_time_s);
  EXPECT_EQ(b.reference_delay_ticks, a.reference_delay_ticks);
  ASSERT_EQ(b.shaper.taps, a.shaper.taps);
  for (std::size_t k = 0; k < a.shaper.taps; ++k)
    EXPECT_NEAR(b.shaper.weight[k], a.shaper.weight[k], 1e-8);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(b.model[i].linear_weight, a.model[i].linear_weight, 1e-9);
    EXPECT_NEAR(b.model[i].creep_gain, a.model[i].creep_gain, 1e-9);
    for (std::size_t k = 0; k < a.model[i].operators; ++k)
      EXPECT_NEAR(b.model[i].weight[k], a.model[i].weight[k], 1e-9);
  }
  // A record with a missing tick is refused, naming the file and the line.
  {
    const auto t = piezoshift::io::CsvTable::load(excitation);
    piezoshift::io::CsvWriter w(
        path("gap.csv"), {"t_s", "u1_um", "u2_um", "u3_um", "sgs1_um", "sgs2_um", "sgs3_um"});
    std::vector<std::vector<double>> cols;
    for (const char* name : {"t_s", "u1_um", "u2_um", "u3_um", "sgs1_um", "sgs2_um", "sgs3_um"})
      cols.push_back(t.column(name));
    for (std::size_t k = 0; k < t.rows(); ++k)
      if (k != 500)
        w.row({cols[0][k], cols[1][k], cols[2][k], cols[3][k], cols[4][k], cols[5][k], cols[6][k]});
    w.close();
  }
  const CliResult gap = run("fit improved --data '" + path("gap.csv") + "'");
  EXPECT_EQ(gap.status, 2);
  EXPECT_NE(gap.err.find("gap.csv:502: t_s steps by 0.002 s"), std::string::npos) << gap.err;
  // The records are written (atomically) before the calibration file, so the file's
  // presence implies them whole; each promises its rows, and `fit improved` refuses a copy cut
  // short, at a line end or within a line, naming the file.
  namespace fs = std::filesystem;
  EXPECT_LE(fs::last_write_time(excitation), fs::last_write_time(cal));
  EXPECT_LE(fs::last_write_time(mode), fs::last_write_time(cal));
  const std::string text = piezoshift::testing::slurp(excitation);
  const std::size_t rows = piezoshift::io::CsvTable::load(excitation).rows();
  EXPECT_NE(text.find(fmt::format("\n# rows = {}\n", rows)), std::string::npos);
  EXPECT_NE(piezoshift::testing::slurp(mode).find(
                fmt::format("\n# rows = {}\n", piezoshift::io::CsvTable::load(mode).rows())),
            std::string::npos);
  const auto cut = [&](const std::string& name, std::size_t bytes) {
    std::ofstream(path(name), std::ios::binary) << text.substr(0, bytes);
    return run("fit improved --data '" + path(name) + "'");
  };
  const std::size_t half = text.size() / 2;
  const CliResult at_line = cut("at_line.csv", text.find('\n', half) + 1);
  EXPECT_EQ(at_line.status, 2);
  EXPECT_NE(at_line.err.find("at_line.csv: "), std::string::npos) << at_line.err;
  EXPECT_NE(at_line.err.find(fmt::format(" data rows where the file promises {} (# rows = {}): "
                                         "the file is cut short",
                                         rows, rows)),
            std::string::npos)
      << at_line.err;
  const CliResult in_line = cut("in_line.csv", text.find('\n', half) - 3);
  EXPECT_EQ(in_line.status, 2);
  EXPECT_NE(in_line.err.find("in_line.csv:"), std::string::npos) << in_line.err;
  EXPECT_NE(in_line.err.find(": the last line has no line end: the file is cut short"),
            std::string::npos)
      << in_line.err;
  std::ofstream(path("mode_cut.csv"), std::ios::binary)
      << piezoshift::testing::slurp(mode).substr(0, piezoshift::testing::slurp(mode).size() - 40);
  const CliResult mode_cut =
      run("fit improved --data '" + excitation + "' --mode-data '" + path("mode_cut.csv") + "'");
  EXPECT_EQ(mode_cut.status, 2);
  EXPECT_NE(mode_cut.err.find("mode_cut.csv"), std::string::npos) << mode_cut.err;
  EXPECT_NE(mode_cut.err.find("cut short"), std::string::npos) << mode_cut.err;
  const CliResult guided =
      run("calibrate --controller improved --daq sim --interferometer sim "
          "--out '" +
          path("g.toml") + "'");
  EXPECT_EQ(guided.status, 2);
}

}  // namespace
