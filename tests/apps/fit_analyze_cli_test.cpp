// Runs `piezoshift fit` and `piezoshift analyze` on CSV files written here: JSON keys and values
// against known truth and hand calculations, free column order and extra columns, and every kind
// of bad input exiting with status 2 and a message naming the file, the line and the column.
#include <cmath>
#include <filesystem>
#include <string>

#include <fmt/core.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../support/cli_test.hpp"
#include "piezoshift/control/cubic_polynomial.hpp"
#include "piezoshift/control/transmission_matrix.hpp"
#include "piezoshift/io/plot.hpp"

namespace {

using piezoshift::testing::CliResult;

const piezoshift::control::Mat3 kPaperA = piezoshift::control::TransmissionMatrix{}.a;
const piezoshift::control::CubicPolynomial kPaperP;

// Poses with Z on a small grid and S = A Z exactly (17 significant digits survive the CSV),
// columns in a scrambled order with two extra columns and comments.
std::string matrix_csv(int poses) {
  std::string s = "# recorded poses\nz3_um,s1_um,note,z1_um,s2_um,t_s,s3_um,z2_um\n";
  for (int i = 0; i < poses; ++i) {
    const double z[3] = {1.0 + (i % 3), 2.0 + 0.5 * ((i / 3) % 3), 0.5 + 1.5 * (i % 4)};
    double sv[3];
    for (int r = 0; r < 3; ++r)
      sv[r] = kPaperA[r][0] * z[0] + kPaperA[r][1] * z[1] + kPaperA[r][2] * z[2];
    s += fmt::format("{:.17g},{:.17g},pose{},{:.17g},{:.17g},{},{:.17g},{:.17g}\n", z[2], sv[0], i,
                     z[0], sv[1], i, sv[2], z[1]);
  }
  return s;
}

class FitAnalyzeCli : public piezoshift::testing::CliTest {
 protected:
  // Bad input: exit 2, nothing on stdout, and every given piece in the message.
  void expect_refused(const std::string& args, std::initializer_list<std::string> pieces) {
    const CliResult r = run(args);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.err;
    EXPECT_EQ(r.out, "") << args;
    for (const auto& piece : pieces)
      EXPECT_NE(r.err.find(piece), std::string::npos) << "'" << piece << "' not in: " << r.err;
  }
};

TEST_F(FitAnalyzeCli, FitMatrixJsonRecoversThePapersAFromReorderedColumns) {
  const std::string f = write("poses.csv", matrix_csv(12));
  const CliResult r = run("fit matrix --json --data '" + f + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("poses").get<int>(), 12);
  ASSERT_EQ(j.at("A").size(), 3u);
  for (int row = 0; row < 3; ++row) {
    ASSERT_EQ(j.at("A")[row].size(), 3u);
    for (int col = 0; col < 3; ++col)
      EXPECT_NEAR(j.at("A")[row][col].get<double>(), kPaperA[row][col], 1e-9) << row << col;
  }
  EXPECT_LT(j.at("rms_residual_um").get<double>(), 1e-12);
  // cond(A) of the paper's A: singular values 1.0774, 0.7824, 0.7121 -> 1.5131.
  EXPECT_NEAR(j.at("condition_number").get<double>(), 1.5131, 1e-4);
  EXPECT_TRUE(j.at("design_condition_number").is_number());
}

TEST_F(FitAnalyzeCli, FitPolyJsonRecoversThePapersP) {
  std::string csv = "extra,measured_um,command_um\n";
  for (int k = 0; k <= 11; ++k)
    csv += fmt::format("x,{},{:.17g}\n", k, kPaperP(k));
  const CliResult r = run("fit poly --data '" + write("points.csv", csv) + "' --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.at("p").size(), 4u);
  EXPECT_NEAR(j.at("p")[0].get<double>(), -0.0001009, 1e-9);
  EXPECT_NEAR(j.at("p")[1].get<double>(), 0.000389, 1e-9);
  EXPECT_NEAR(j.at("p")[2].get<double>(), 1.014, 1e-9);
  EXPECT_NEAR(j.at("p")[3].get<double>(), 0.2914, 1e-9);
  EXPECT_LT(j.at("rms_residual_um").get<double>(), 1e-12);
  EXPECT_LT(j.at("condition_number").get<double>(), 10.0);  // centred and scaled design
}

TEST_F(FitAnalyzeCli, FitTextOutputNamesTheNumbers) {
  const CliResult r = run("fit matrix --data '" + write("poses.csv", matrix_csv(6)) + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("[ -0.421800   0.603000   0.654700]"), std::string::npos) << r.out;
}

TEST_F(FitAnalyzeCli, FitBadInputExitsTwoNamingFileLineAndColumn) {
  const std::string good = matrix_csv(6);
  // Missing column: the header line is line 2 (after the comment).
  std::string no_z2 = good;
  no_z2.replace(no_z2.find(",z2_um"), 6, ",zz_um");
  const std::string f1 = write("no_z2.csv", no_z2);
  expect_refused("fit matrix --data '" + f1 + "'", {f1 + ":2:", "missing column 'z2_um'"});
  // Text where a number belongs: data row 3 is line 5; z2_um is field 8.
  std::string text = good;
  std::size_t line_start = 0;
  for (int line = 1; line < 5; ++line)
    line_start = text.find('\n', line_start) + 1;
  const std::size_t last_comma = text.rfind(',', text.find('\n', line_start));
  text.replace(last_comma + 1, text.find('\n', line_start) - last_comma - 1, "abc");
  const std::string f2 = write("text.csv", text);
  expect_refused("fit matrix --data '" + f2 + "'",
                 {f2 + ":5: column 'z2_um' (field 8): 'abc' is not a number"});
  // NaN.
  std::string nan = text;
  nan.replace(nan.find(",abc"), 4, ",nan");
  const std::string f3 = write("nan.csv", nan);
  expect_refused("fit matrix --data '" + f3 + "'",
                 {f3 + ":5: column 'z2_um' (field 8): 'nan' is not a finite number"});
  // Too few rows.
  const std::string f4 = write("two.csv", matrix_csv(2));
  expect_refused("fit matrix --data '" + f4 + "'", {f4 + ": matrix fit: 2 poses; at least 3"});
  const std::string f5 = write("four.csv", "measured_um,command_um\n0,0\n1,1\n2,2\n3,3\n");
  expect_refused("fit poly --data '" + f5 + "'", {f5 + ": polynomial fit: 4 points; at least 5"});
  // Missing file.
  const std::string f6 = path("absent.csv");
  expect_refused("fit poly --data '" + f6 + "'", {f6 + ": cannot open"});
  // Rank-deficient: z3 = z1 + z2 on every pose.
  std::string dep = "s1_um,s2_um,s3_um,z1_um,z2_um,z3_um\n";
  for (int i = 0; i < 5; ++i)
    dep += fmt::format("{},{},{},{},{},{}\n", i, 2 * i + 1, 3 - i, i, 1 + i % 2, i + 1 + i % 2);
  const std::string f7 = write("dependent.csv", dep);
  expect_refused("fit matrix --data '" + f7 + "'", {f7 + ": matrix fit:", "rank-deficient"});
  const std::string f8 =
      write("three_levels.csv", "measured_um,command_um\n0,0\n0,0\n5,5\n5,5\n10,10\n10,10\n");
  expect_refused("fit poly --data '" + f8 + "'", {f8 + ": polynomial fit:", "rank-deficient"});
}

TEST_F(FitAnalyzeCli, AnalyzeLinearityHandCalculation) {
  // See tests/experiments/metrics_linearity_test.cpp: zero-end 0.75 %, best-fit 0.45 %.
  const std::string f = write("lin.csv",
                              "measured_um,comment,zd_um\n0,a,0\n1.01,b,1\n2.03,c,2\n"
                              "3.02,d,3\n4.00,e,4\n\n");
  const CliResult r = run("analyze linearity --data '" + f + "' --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("n").get<int>(), 5);
  EXPECT_NEAR(j.at("linearity_zero_end_pct").get<double>(), 0.75, 1e-9);
  EXPECT_NEAR(j.at("linearity_best_fit_pct").get<double>(), 0.45, 1e-9);
}

TEST_F(FitAnalyzeCli, AnalyzeRepeatabilityHandCalculation) {
  // Deviations 0, +2, -2, +1, -1 nm: e_R = sqrt(10 / 4) = 1.5811 nm.
  const std::string f =
      write("rep.csv", "run,measured_um\n1,10.000\n2,10.002\n3,9.998\n4,10.001\n5,9.999\n");
  const CliResult r = run("analyze repeatability --data '" + f + "' --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("n").get<int>(), 5);
  EXPECT_NEAR(j.at("repeatability_nm").get<double>(), std::sqrt(2.5), 1e-9);
}

TEST_F(FitAnalyzeCli, AnalyzeStepFirstOrderAndItsFigure) {
  // 11 um, tau = 10 ms, sampled at 10 kHz for 0.2 s: rise tau ln 9, 2 % settling tau ln 50.
  std::string csv = "t_s,measured_um\n";
  for (int k = 0; k <= 2000; ++k)
    csv += fmt::format("{:.4f},{:.12f}\n", k * 1e-4, 11.0 * (1 - std::exp(-k * 1e-4 / 0.01)));
  const std::string f = write("step.csv", csv);
  const std::string fig = path("fig/step.png");
  std::filesystem::create_directory(path("fig"));  // --plot creates no folder (docs/safety.md)
  const bool draw = piezoshift::io::find_gnuplot().has_value();
  const CliResult r =
      run("analyze step --json --data '" + f + "'" + (draw ? " --plot '" + fig + "'" : ""));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j.at("rise_time_s").get<double>(), 0.01 * std::log(9.0), 1e-5);
  EXPECT_NEAR(j.at("settling_time_pct_s").get<double>(), 0.01 * std::log(50.0), 1e-5);
  EXPECT_NEAR(j.at("overshoot_pct").get<double>(), 0.0, 1e-6);
  if (draw) {
    EXPECT_GT(std::filesystem::file_size(fig), 1000u);
    EXPECT_TRUE(std::filesystem::exists(path("fig/step.gp")));
  }
}

TEST_F(FitAnalyzeCli, AnalyzeBadInputExitsTwo) {
  const std::string f1 = write("nan.csv", "zd_um,measured_um\n0,0\n1,NaN\n2,2\n");
  expect_refused("analyze linearity --data '" + f1 + "'",
                 {f1 + ":3: column 'measured_um' (field 2): 'NaN' is not a finite number"});
  const std::string f2 = write("one.csv", "measured_um\n5.0\n");
  expect_refused("analyze repeatability --data '" + f2 + "'",
                 {f2 + ": repeatability: 1 value; Eq. 9 needs at least 2"});
  const std::string f3 = write("cols.csv", "desired,measured_um\n0,0\n");
  expect_refused("analyze linearity --data '" + f3 + "'", {f3 + ":1: missing column 'zd_um'"});
  const std::string f4 = write("short.csv", "zd_um,measured_um\n0,0\n1\n");
  expect_refused("analyze linearity --data '" + f4 + "'",
                 {f4 + ":3: 1 fields, but the header (line 1) has 2"});
}

}  // namespace
