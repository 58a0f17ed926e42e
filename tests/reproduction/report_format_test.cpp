// How reports and tables print numbers (figure_format.hpp), align the terminal's tables
// (text_table.hpp) and judge Table 4 against the paper's bands (paper_bands.hpp): no simulation.
#include <gtest/gtest.h>

#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "piezoshift/reproduction/figure_format.hpp"
#include "piezoshift/reproduction/paper_bands.hpp"
#include "piezoshift/reproduction/text_table.hpp"

namespace piezoshift::reproduction {
namespace {

TEST(FigureFormat, EachUnitToThePrecisionItCarries) {
  EXPECT_EQ(format_figure(0.036, "s"), "36 ms");
  EXPECT_EQ(format_figure(0.05805, "s"), "58 ms");
  EXPECT_EQ(format_figure(0.0016, "s"), "1.6 ms");
  EXPECT_EQ(format_figure(std::numeric_limits<double>::infinity(), "s"), "not settled");
  EXPECT_EQ(format_figure(13.0, "um"), "13.00 µm");
  EXPECT_EQ(format_figure(11.4, "um", 0.1), "11.4 µm");
  EXPECT_EQ(format_figure(0.07682, "%"), "0.077 %");
  EXPECT_EQ(format_figure(0.21, "%"), "0.21 %");
  EXPECT_EQ(format_figure(2.0, "nm"), "2.0 nm");
  EXPECT_EQ(format_figure(0.0642, "nm"), "0.064 nm");
  EXPECT_EQ(format_figure(8.85, "dB"), "8.8 dB");
  EXPECT_EQ(format_figure(93.64, "deg"), "93.6°");
  // Exactly 0 is said as 0, not as a string of zeros that reads like a placeholder.
  EXPECT_EQ(format_figure(0.0, "%"), "0 %");
}

TEST(TextTable, ColumnsAlignInCharactersWhateverTheRowLength) {
  const std::string t = text_table({{"figure", "paper", "oracle"},
                                    {"a very long label of an 11 µm step, ±2 %", "36 ms", "0 %"},
                                    {"short", "2.0 nm", "1.5 nm"}});
  std::istringstream in(t);
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);)
    lines.push_back(l);
  ASSERT_EQ(lines.size(), 4U);  // header, rule, two rows
  // Right-aligned last columns end in the same character column on every row.
  EXPECT_EQ(display_width(lines[0]), display_width(lines[2]));
  EXPECT_EQ(display_width(lines[2]), display_width(lines[3]));
  EXPECT_EQ(display_width(lines[1]), display_width(lines[2]));
  EXPECT_EQ(lines[3].substr(0, 7), "  short");
  EXPECT_EQ(display_width("±2 µm"), 5U);
}

TEST(PaperBands, EachFigureIsJudgedAgainstItsBand) {
  ExperimentSet e;
  e.travel.open_loop_um = 13.05;
  e.travel.semi_closed_um = 11.5;
  e.step.metrics.settling_time_pct_s = 0.036;
  e.linearity.metrics.linearity_zero_end_pct = 0.025;
  e.repeat_5um.metrics.repeatability_nm = 2.0;
  e.repeat_10um.metrics.repeatability_nm = 4.6;
  e.repeat_10um.validity.valid = true;
  const std::vector<PaperBandRow> rows = paper_band_rows(e);
  ASSERT_EQ(rows.size(), 6U);
  EXPECT_EQ(rows[0].verdict(), "within");
  EXPECT_EQ(rows[1].twin, "11.5 µm");
  EXPECT_EQ(rows[2].figure.substr(0, 9), "Figure 10");
  EXPECT_EQ(rows[2].verdict(), "within");
  EXPECT_EQ(rows[3].band, "0.1 to 0.4 %");
  EXPECT_EQ(rows[3].verdict(), "outside (below)");
  EXPECT_EQ(rows[4].verdict(), "within");
  EXPECT_EQ(rows[5].verdict(), "outside (above)");
  e.step.validity.fail("did not settle");
  EXPECT_EQ(paper_band_rows(e)[2].verdict(), "not valid");
  EXPECT_EQ(paper_band_rows(e)[2].twin, "NOT VALID: did not settle");
}

}  // namespace
}  // namespace piezoshift::reproduction
