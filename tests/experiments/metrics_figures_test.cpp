#include "piezoshift/experiments/metrics_figures.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace piezoshift::experiments {
namespace {

namespace fs = std::filesystem;

fs::path out_dir() {
  const auto dir = fs::path(testing::TempDir()) / "piezoshift_figures";
  fs::create_directories(dir);
  return dir;
}

TEST(MetricsFigures, StepFigureHasBothBandsAroundTheFinalValue) {
  std::vector<double> t, y;
  for (int k = 0; k <= 500; ++k) {
    t.push_back(k * 1e-3);
    y.push_back(11.0 * (1 - std::exp(-t.back() / 0.02)));
  }
  const StepResponseOptions o;
  const StepResponseMetrics m = step_response_metrics(t, y, o);
  const io::Figure f = step_response_figure(t, y, m, o);
  ASSERT_EQ(f.panels.size(), 2u);
  const io::Series& band = f.panels[0].series[0];
  ASSERT_EQ(band.style, io::SeriesStyle::kBand);
  EXPECT_NEAR(band.y[0], m.final_um - 0.02 * 11.0, 1e-6);  // +-2 % of the 11 um step
  EXPECT_NEAR(band.w[0], m.final_um + 0.02 * 11.0, 1e-6);
  EXPECT_NEAR(f.panels[1].series[0].w[0], 10.0, 0.0);  // +-10 nm in the zoom, in nm
  if (!io::find_gnuplot())
    GTEST_SKIP() << "gnuplot not on PATH";
  const io::PlotFiles files = io::render(f, out_dir() / "step");
  EXPECT_GT(fs::file_size(*files.png), 1000u);
}

TEST(MetricsFigures, LinearityAndRepeatabilityFiguresRender) {
  const std::vector<double> x{0, 1, 2, 3, 4}, y{0, 1.01, 2.03, 3.02, 4.00};
  const LinearityMetrics m = linearity_metrics(x, y);
  const io::Figure lin = linearity_figure(x, y, m);
  // Deviations are drawn in nm: the 0.03 um zero-end deviation at x = 2 is 30 nm.
  EXPECT_NEAR(lin.panels[1].series[0].y[2], 30.0, 1e-9);

  const std::vector<RepeatabilitySet> sets{{"5 um", {5.000, 5.002, 4.998, 5.001, 4.999}},
                                           {"10 um", {10.0, 10.003, 9.997, 10.0}}};
  const io::Figure rep = repeatability_figure(sets);
  ASSERT_EQ(rep.panels.size(), 2u);
  EXPECT_EQ(rep.cols, 2);
  EXPECT_EQ(rep.panels[0].title, "5 um: e_R = 1.58 nm (n = 5)");
  if (!io::find_gnuplot())
    GTEST_SKIP() << "gnuplot not on PATH";
  EXPECT_GT(fs::file_size(*io::render(lin, out_dir() / "linearity").png), 1000u);
  EXPECT_GT(fs::file_size(*io::render(rep, out_dir() / "repeatability").png), 1000u);
}

// Data spread over microns (reproduce's own linearity.csv, 0 to 11 um) needed more than
// the histogram's 10000 bins of 1 nm: the bin widens to 1, 2 or 5 x 10^k nm, named on the axis.
TEST(MetricsFigures, RepeatabilityHistogramWidensItsBinForMicronSpreads) {
  EXPECT_EQ(histogram_bin_nm(4.0, 1.0), 1.0);
  EXPECT_EQ(histogram_bin_nm(11000.0, 1.0), 50.0);   // 22 nm at least: 50 nm
  EXPECT_EQ(histogram_bin_nm(60000.0, 1.0), 200.0);  // 120 nm at least: 200 nm
  std::vector<RepeatabilitySet> sets{{"sweep", {}}};
  for (int i = 0; i <= 11; ++i)
    sets[0].measured_um.push_back(i);
  const io::Figure f = repeatability_figure(sets);
  ASSERT_EQ(f.panels.size(), 1u);
  EXPECT_EQ(f.panels[0].series[0].w.front(), 50.0);
  EXPECT_LE(f.panels[0].series[0].x.size(), 500u);
  EXPECT_NE(f.panels[0].x_label.find("bins of 50 nm"), std::string::npos) << f.panels[0].x_label;
}

}  // namespace
}  // namespace piezoshift::experiments
