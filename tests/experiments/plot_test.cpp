#include "piezoshift/io/plot.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <vector>

#include "piezoshift/core/input_error.hpp"

namespace piezoshift::io {
namespace {

namespace fs = std::filesystem;

fs::path temp_dir(const std::string& name) {
  const auto dir = fs::path(testing::TempDir()) / "piezoshift_plot" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Width and height from a PNG's IHDR chunk (big-endian, bytes 16..23).
std::pair<std::uint32_t, std::uint32_t> png_size(const fs::path& p) {
  const std::string b = read(p);
  if (b.size() < 24 || b.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0)
    return {0, 0};
  auto be32 = [&](std::size_t i) {
    return (std::uint32_t(std::uint8_t(b[i])) << 24) |
           (std::uint32_t(std::uint8_t(b[i + 1])) << 16) |
           (std::uint32_t(std::uint8_t(b[i + 2])) << 8) | std::uint32_t(std::uint8_t(b[i + 3]));
  };
  return {be32(16), be32(20)};
}

Figure two_panel_figure() {
  const std::vector<double> t{0, 1, 2, 3}, y{0, 0.8, 1.02, 1.0}, e{1, -2, 3, 0};
  Figure f;
  f.title = "it's a test";  // a quote inside a gnuplot string
  f.rows = 2;
  f.width_px = 640;
  f.height_px = 480;
  f.png_scale = 1.0;  // PNG pixels = points, and no SVG unless a test asks
  f.svg = false;
  Panel a;
  a.title = "response of s1_um";
  a.x_label = "time [s]";
  a.y_label = "z [um]";
  a.series.push_back(line_series("measured", t, y));
  a.series.push_back(band_series("+-2 %", 0, 3, 0.98, 1.02));
  a.markers.push_back({true, 0.5, "step"});
  Panel b;
  b.series.push_back(point_series("error", t, e));
  b.markers.push_back({false, 0.0, ""});
  b.key = "off";
  f.panels = {a, b};
  return f;
}

TEST(Plot, ScriptAndDataAreWrittenBesideTheFigure) {
  const fs::path dir = temp_dir("files");
  const PlotFiles files = write_plot_files(two_panel_figure(), dir / "fig.png");
  EXPECT_EQ(files.script, dir / "fig.gp");
  EXPECT_EQ(files.data, dir / "fig.dat");
  const std::string gp = read(files.script);
  EXPECT_NE(gp.find("set terminal pngcairo noenhanced size 640,480"), std::string::npos);
  EXPECT_NE(gp.find("datafile = 'fig.dat'"), std::string::npos);  // relative: restylable
  EXPECT_NE(gp.find("set multiplot layout 2,1 title 'it''s a test'"), std::string::npos);
  // The band (index 1) is drawn before the curve (index 0).
  EXPECT_LT(gp.find("datafile index 1 using 1:2:3 with filledcurves"),
            gp.find("datafile index 0 using 1:2 with lines"));
  EXPECT_EQ(gp.find("set terminal svg"), std::string::npos);
  const std::string dat = read(files.data);
  EXPECT_NE(dat.find("# index 2: panel 2, 'error'\n0 1\n1 -2\n2 3\n3 0\n"), std::string::npos);
  EXPECT_NE(dat.find("0 0.98 1.02\n3 0.98 1.02\n"), std::string::npos);
}

TEST(Plot, GnuplotDrawsPngOfTheRequestedSizeAndSvg) {
  if (!find_gnuplot())
    GTEST_SKIP() << "gnuplot not on PATH";
  const fs::path dir = temp_dir("render");
  Figure f = two_panel_figure();
  f.svg = true;
  const PlotFiles files = render(f, dir / "fig");
  ASSERT_TRUE(files.png && files.svg);
  EXPECT_GT(fs::file_size(*files.png), 1000u);
  EXPECT_EQ(png_size(*files.png), (std::pair<std::uint32_t, std::uint32_t>{640, 480}));
  const std::string svg = read(*files.svg);
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  EXPECT_NE(svg.find("width=\"640\""), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "fig.gnuplot.log"));  // removed when gnuplot said nothing
}

TEST(Plot, GnuplotErrorsComeBackWithItsMessage) {
  if (!find_gnuplot())
    GTEST_SKIP() << "gnuplot not on PATH";
  Figure f = two_panel_figure();
  f.panels[0].key = "nowhere_at_all";  // not a gnuplot key position
  try {
    render(f, temp_dir("bad") / "fig");
    FAIL() << "no error";
  } catch (const PlotError& e) {
    EXPECT_NE(std::string(e.what()).find("gnuplot failed on"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("fig.gp"), std::string::npos) << e.what();
  }
}

TEST(Plot, MissingGnuplotIsAClearError) {
  PlotOptions o;
  o.gnuplot = "gnuplot-that-does-not-exist";
  try {
    render(two_panel_figure(), temp_dir("missing") / "fig", o);
    FAIL() << "no error";
  } catch (const PlotError& e) {
    EXPECT_NE(std::string(e.what()).find("'gnuplot-that-does-not-exist' not found on PATH"),
              std::string::npos)
        << e.what();
  }
}

// A data file's name with a line break, once written unescaped into a comment of the script,
// put its next line into gnuplot's command stream, and gnuplot's `system` ran a shell. Titles,
// labels and names with line breaks, quotes and backslashes stay inside their comment or string.
TEST(Plot, NoTitleLabelOrNameReachesGnuplotsCommandStream) {
  const fs::path dir = temp_dir("hostile");
  const fs::path pwned = dir / "PWNED";
  const std::string hostile =
      "a\nsystem('touch " + pwned.string() + "')\r\n# b' \\' c\\\n!touch " + pwned.string();
  Figure f = two_panel_figure();
  f.title = hostile;
  f.panels[0].title = f.panels[0].x_label = f.panels[0].y_label = hostile;
  f.panels[0].series[0].title = hostile;
  f.panels[0].markers[0].label = hostile;
  const PlotFiles files = write_plot_files(f, dir / "fig");
  for (const fs::path& p : {files.script, files.data}) {
    std::istringstream lines(read(p));
    for (std::string line; std::getline(lines, line);) {
      EXPECT_NE(line.rfind("system", 0), 0U) << p << ": " << line;
      EXPECT_NE(line.rfind("!", 0), 0U) << p << ": " << line;
    }
  }
  // A key position is written as it is, so it must be words.
  Figure bad = two_panel_figure();
  bad.panels[0].key = "top\nsystem('id')";
  EXPECT_THROW(write_plot_files(bad, dir / "bad"), std::invalid_argument);
  if (!find_gnuplot())
    return;  // the script's lines were checked; drawing needs gnuplot
  render(f, dir / "fig");
  EXPECT_FALSE(fs::exists(pwned));
}

// --plot once wrote its .gp and .dat through links planted at their names, in place; a
// line break in the name was exit 1; --plot /nonexistent/x.png created /nonexistent. The side
// files replace a planted link (its target untouched), a name with a control character and a
// folder that does not exist are refused, and no folder is created.
TEST(Plot, SideFilesReplacePlantedLinksAndNoFolderIsCreated) {
  const fs::path dir = temp_dir("links");
  const fs::path victim = dir / "victim.txt";
  std::ofstream(victim) << "keep me";
  for (const char* side : {"fig.gp", "fig.dat", "fig.gnuplot.log", "fig.png"})
    fs::create_symlink(victim, dir / side);
  const PlotFiles files = write_plot_files(two_panel_figure(), dir / "fig.png");
  EXPECT_FALSE(fs::is_symlink(files.script));
  EXPECT_FALSE(fs::is_symlink(files.data));
  EXPECT_NE(read(files.script).find("set terminal pngcairo"), std::string::npos);
  if (find_gnuplot()) {
    render(two_panel_figure(), dir / "fig.png");
    EXPECT_FALSE(fs::is_symlink(dir / "fig.png"));
    EXPECT_EQ(png_size(dir / "fig.png"), (std::pair<std::uint32_t, std::uint32_t>{640, 480}));
  }
  EXPECT_EQ(read(victim), "keep me");
  std::size_t temporaries = 0;
  for (const auto& e : fs::directory_iterator(dir))
    temporaries += e.path().filename().string().find(".tmp.") != std::string::npos;
  EXPECT_EQ(temporaries, 0u);

  const auto refusal = [](const std::function<void()>& f) -> std::string {
    try {
      f();
    } catch (const core::InputError& e) {
      return e.what();
    }
    return "no refusal";
  };
  const fs::path missing = dir / "nonexistent" / "x.png";
  EXPECT_EQ(refusal([&] { check_output_path(missing, "--plot"); }),
            "--plot " + missing.string() + ": the folder " + (dir / "nonexistent").string() +
                " does not exist (it is not created)");
  EXPECT_EQ(refusal([&] { write_plot_files(two_panel_figure(), missing); }),
            "plot output " + missing.string() + ": the folder " + (dir / "nonexistent").string() +
                " does not exist");
  EXPECT_FALSE(fs::exists(dir / "nonexistent"));
  const fs::path broken = dir / "a\nb.png";
  EXPECT_EQ(refusal([&] { check_output_path(broken, "--plot"); }),
            "--plot " + (dir / "a b.png").string() +
                ": holds a control character (a line break, a tab ...); give a name without");
  EXPECT_NE(refusal([&] { write_plot_files(two_panel_figure(), broken); }).find("control"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "a\nb.gp"));
}

TEST(Plot, HistogramBinsAlignOnMultiplesOfTheWidth) {
  const std::vector<double> v{0.1, 0.2, 2.7, 2.9, 1.0, -0.5};
  const Series s = histogram_series("h", v, 1.0);
  // Bins [-1,0) [0,1) [1,2) [2,3): counts 1, 2, 1, 2.
  EXPECT_EQ(s.x, (std::vector<double>{-0.5, 0.5, 1.5, 2.5}));
  EXPECT_EQ(s.y, (std::vector<double>{1, 2, 1, 2}));
  EXPECT_EQ(s.w, (std::vector<double>{1, 1, 1, 1}));
  EXPECT_THROW(histogram_series("h", v, 0.0), std::invalid_argument);
  EXPECT_THROW(histogram_series("h", v, 1e-6), std::invalid_argument);  // too many bins
}

TEST(Plot, InconsistentFiguresAreRejected) {
  Figure f = two_panel_figure();
  f.rows = 1;  // 1x1 grid for two panels
  EXPECT_THROW(write_plot_files(f, temp_dir("grid") / "fig"), std::invalid_argument);
  f = two_panel_figure();
  f.panels[0].series[0].y.pop_back();
  EXPECT_THROW(write_plot_files(f, temp_dir("sizes") / "fig"), std::invalid_argument);
  f = two_panel_figure();
  f.panels[1].x_log = true;  // its x starts at 0
  EXPECT_THROW(write_plot_files(f, temp_dir("log") / "fig"), std::invalid_argument);
}

TEST(Plot, ALogarithmicAxisIsSetPerPanel) {
  Figure f = two_panel_figure();
  for (auto& s : f.panels[0].series)
    for (double& x : s.x)
      x += 1.0;
  f.panels[0].x_log = true;
  const std::string gp = read(write_plot_files(f, temp_dir("logscale") / "fig").script);
  const auto first = gp.find("set logscale x\n");
  ASSERT_NE(first, std::string::npos);
  EXPECT_LT(first, gp.find("# panel 2"));
  EXPECT_GT(gp.find("unset logscale x\n"), gp.find("# panel 2"));
}

}  // namespace
}  // namespace piezoshift::io
