// Every figure the commands draw, read back from its SVG
// (support/svg_text_check.hpp): no two pieces of text overlap, every axis label has a unit, no
// unit spelt in ASCII. `reproduce --quick` (Figures 10 to 12, the phase step, the Bode plot, the
// measurement's surface and Zernike chart), `psi simulate` and `psi analyze` (the surface map with
// its colour bar in nm) and `measure` (surface, Zernike, steps, stage). `compare`'s figures are
// checked where it runs anyway (CompareCommand, acceptance).
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../support/cli_test.hpp"
#include "../support/svg_text_check.hpp"
#include "piezoshift/io/plot.hpp"

namespace piezoshift {
namespace {

namespace fs = std::filesystem;

class FiguresCli : public testing::CliTest {
 protected:
  void SetUp() override {
    CliTest::SetUp();
    if (!io::find_gnuplot())
      GTEST_SKIP() << "gnuplot not on PATH";
  }
  // Checks every SVG of dir and that there are at least `least` of them, each with a PNG beside.
  void expect_clean_figures(const std::string& dir, int least) {
    int figures = 0;
    const std::vector<std::string> problems = testing::folder_figure_problems(dir, figures);
    std::string all;
    for (const auto& p : problems)
      all += p + "\n";
    EXPECT_EQ(all, "") << dir;
    EXPECT_GE(figures, least) << dir;
    for (const auto& e : fs::directory_iterator(dir)) {
      if (e.path().extension() == ".svg") {
        EXPECT_TRUE(fs::exists(fs::path(e.path()).replace_extension(".png"))) << e.path();
      }
    }
  }
};

TEST_F(FiguresCli, ReproduceDrawsCleanFigures) {
  const testing::CliResult r = run("reproduce --quick --json --out '" + path("r") + "'");
  ASSERT_TRUE(r.status == 0 || r.status == 4) << r.err;
  expect_clean_figures(path("r"), 7);
  // The report prints each figure's caption under it, with its key numbers, after the image.
  const std::string md = testing::read_whole_file(path("r") + "/report.md");
  const std::size_t fig10 = md.find("fig10_step_response.png");
  ASSERT_NE(fig10, std::string::npos);
  EXPECT_NE(md.find("Step response: settled to ±2 %: ", fig10), std::string::npos);
  EXPECT_NE(md.find("Repeatability histograms with the normal density of σ = e_R: 5 µm", fig10),
            std::string::npos);
}

TEST_F(FiguresCli, PsiSurfaceMapHasANumberedColourBarInNanometres) {
  ASSERT_EQ(run("psi simulate --out '" + path("sim") + "' --size 64 --no-budget").status, 0);
  expect_clean_figures(path("sim"), 1);
  std::string frames;
  for (int k = 0; k < 5; ++k)
    frames += " '" + path("sim") + "/frame_0" + std::to_string(k) + ".png'";
  const testing::CliResult r = run("psi analyze" + frames + " --mask '" + path("sim") +
                                   "/mask.png' --out '" + path("a") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  expect_clean_figures(path("a"), 1);
  const std::string gp = testing::read_whole_file(path("a") + "/surface_nm.gp");
  EXPECT_NE(gp.find("set cblabel 'height [nm]'"), std::string::npos);
}

TEST_F(FiguresCli, MeasureDrawsCleanFigures) {
  const std::string cam =
      write("cam.toml", "[camera]\nwidth_px = 96\nheight_px = 96\npixel_format = \"Mono12\"\n");
  const testing::CliResult r =
      run("measure --free-run --json --config '" + cam + "' --out '" + path("m") + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  expect_clean_figures(path("m"), 4);
}

}  // namespace
}  // namespace piezoshift
