// The text of every figure, read back from the SVG gnuplot draws (support/
// svg_text_check.hpp): no two pieces of text overlap, every axis label has a unit, no unit in
// ASCII. First the checker itself on figures made to fail it, then the paper's Figures 10 to 12
// as the report draws them (on made-up data: the real commands' figures are checked in
// tests/apps/figures_cli_test.cpp and the acceptance tests).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "../support/svg_text_check.hpp"
#include "piezoshift/experiments/metrics_figures.hpp"

namespace piezoshift::experiments {
namespace {

namespace fs = std::filesystem;
using testing::figure_text_problems;

fs::path out_dir(const std::string& name) {
  const auto dir = fs::path(::testing::TempDir()) / "piezoshift_figure_text" / name;
  fs::create_directories(dir);
  return dir;
}

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v)
    s += x + "\n";
  return s;
}

bool mentions(const std::vector<std::string>& problems, const std::string& piece) {
  for (const auto& p : problems)
    if (p.find(piece) != std::string::npos)
      return true;
  return false;
}

io::Figure svg_only(io::Figure f) {
  f.png = false;
  f.svg = true;
  return f;
}

TEST(SvgTextCheck, BoxesFollowAnchorAndRotation) {
  const std::string svg =
      "<g transform=\"translate(100.00,50.00)\" font-size=\"10.00\" text-anchor=\"end\">\n"
      "<text>abcd</text></g>\n"
      "<g transform=\"translate(20.00,200.00) rotate(270)\" font-size=\"10.00\" "
      "text-anchor=\"middle\">\n<text>height [µm]</text></g>\n";
  const auto t = testing::svg_texts(svg);
  ASSERT_EQ(t.size(), 2u);
  EXPECT_NEAR(t[0].x0, 100.0 - 4 * 5.5, 1e-9);  // ends at its anchor, 0.55 em per character
  EXPECT_NEAR(t[0].x1, 100.0, 1e-9);
  EXPECT_NEAR(t[0].y0, 50.0 - 7.5, 1e-9);
  // Rotated upwards: 11 characters (µ is one) along y, centred on 200; the font's height along x.
  EXPECT_NEAR(t[1].y1 - t[1].y0, 11 * 5.5, 1e-9);
  EXPECT_NEAR(0.5 * (t[1].y0 + t[1].y1), 200.0, 1e-9);
  EXPECT_NEAR(t[1].x1 - t[1].x0, 9.5, 1e-9);
}

TEST(SvgTextCheck, UnitsAreBracketedOrCounted) {
  EXPECT_TRUE(testing::has_unit("time [s]"));
  EXPECT_TRUE(testing::has_unit("z − mean [nm]; mean 5.0002 µm"));
  EXPECT_TRUE(testing::has_unit("count"));
  EXPECT_FALSE(testing::has_unit("displacement"));
  EXPECT_FALSE(testing::has_unit("displacement []"));
}

// The checker must be able to fail: text placed on text, an axis without unit and a unit in
// ASCII are each found in a figure drawn by gnuplot.
TEST(SvgTextCheck, FlagsAFigureMadeToFail) {
  if (!io::find_gnuplot())
    GTEST_SKIP() << "gnuplot not on PATH";
  const std::vector<double> x{0, 1, 2}, y{0, 1, 4};
  io::Figure f;
  io::Panel p;
  p.x_label = "displacement";  // no unit
  p.y_label = "z [um]";        // ASCII
  p.series.push_back(io::line_series("data", x, y));
  p.labels.push_back({.x = 0.3, .y = 0.5, .text = "settled to 2 % at 0.036 s"});
  p.labels.push_back({.x = 0.32, .y = 0.5, .text = "settled to 10 nm at 0.058 s"});
  f.panels.push_back(p);
  const io::PlotFiles files = io::render(svg_only(f), out_dir("bad") / "bad");
  const std::vector<std::string> problems = figure_text_problems(*files.svg);
  EXPECT_TRUE(mentions(problems, "text overlaps: 'settled to 2 % at 0.036 s'")) << joined(problems);
  EXPECT_TRUE(mentions(problems, "axis label without unit: 'displacement'")) << joined(problems);
  EXPECT_TRUE(mentions(problems, "unit in ASCII: 'z [um]'")) << joined(problems);

  // The same labels one above the other, with units: nothing to say.
  f.panels[0].x_label = "displacement [µm]";
  f.panels[0].y_label = "z [µm]";
  f.panels[0].labels[1].y = 0.4;
  const io::PlotFiles good = io::render(svg_only(f), out_dir("good") / "good");
  EXPECT_EQ(joined(figure_text_problems(*good.svg)), "");
}

// Figures 10 to 12 as the report draws them: no overlapping text, units everywhere, and the key
// numbers (settling times, e_R) written on the figure.
TEST(FigureText, PaperFiguresPassTheTextChecks) {
  if (!io::find_gnuplot())
    GTEST_SKIP() << "gnuplot not on PATH";
  std::vector<double> t, y;
  for (int k = 0; k <= 1000; ++k) {
    t.push_back(k * 1e-3);
    y.push_back(t.back() < 0.01 ? 0.0 : 11.0 * (1 - std::exp(-(t.back() - 0.01) / 0.01)));
  }
  StepResponseOptions so;
  so.step_time_s = 0.01;
  const StepResponseMetrics sm = step_response_metrics(t, y, so);
  const fs::path dir = out_dir("paper");
  const auto f10 = io::render(
      svg_only(step_response_figure(t, y, sm, so, "Step response to 11 µm")), dir / "fig10");
  std::vector<double> xd, yd;
  for (int k = 0; k <= 11; ++k) {
    xd.push_back(k);
    yd.push_back(k * 1.0005 + 0.004 * std::sin(k));
  }
  const LinearityMetrics lm = linearity_metrics(xd, yd);
  io::render(svg_only(linearity_figure(xd, yd, lm, "Linearity")), dir / "fig11");
  std::vector<RepeatabilitySet> sets{{"5 µm", {}}, {"10 µm", {}}};
  for (int k = 0; k < 230; ++k) {
    sets[0].measured_um.push_back(5.0 + 0.002 * std::sin(1.7 * k));
    sets[1].measured_um.push_back(10.0 + 0.003 * std::cos(2.3 * k));
  }
  const auto f12 =
      io::render(svg_only(repeatability_figure(sets, 1.0, "Repeatability")), dir / "fig12");
  int figures = 0;
  EXPECT_EQ(joined(testing::folder_figure_problems(dir, figures)), "");
  EXPECT_EQ(figures, 3);
  const std::string svg10 = testing::read_whole_file(*f10.svg);
  EXPECT_NE(svg10.find(fmt::format("{:.3f} s", sm.settling_time_pct_s)), std::string::npos);
  EXPECT_NE(svg10.find(fmt::format("{:.3f} s", sm.settling_time_abs_s)), std::string::npos);
  const std::string svg12 = testing::read_whole_file(*f12.svg);
  EXPECT_NE(svg12.find("+1 σ = "), std::string::npos);
  EXPECT_NE(svg12.find("e_R: sample standard deviation σ"), std::string::npos);
}

}  // namespace
}  // namespace piezoshift::experiments
