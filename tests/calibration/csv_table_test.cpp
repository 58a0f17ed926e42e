#include "piezoshift/io/csv_table.hpp"

#include <gtest/gtest.h>

#include <fmt/format.h>

#include <string>
#include <vector>

#include "piezoshift/core/input_error.hpp"

#include "../support/temp_dir_test.hpp"
#include "heap_peak.hpp"

namespace piezoshift::io {
namespace {

std::string error_of(std::string_view text, std::string_view column = {}) {
  try {
    const CsvTable t = CsvTable::parse(text, "data.csv");
    if (!column.empty())
      t.column(column);
  } catch (const core::InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(CsvTable, SelectsColumnsByNameInAnyOrderIgnoringExtras) {
  const CsvTable t = CsvTable::parse(
      "\xEF\xBB\xBF# recorded 2017-03-12\r\n"
      "note, z2_um ,\"s1_um\",time_s\r\n"
      "\r\n"
      "7, 1.25e-1, +3 ,0\r\n"
      "# a comment between rows\n"
      "8,-2,  4.5\t,1e-3\n"
      "\n\n",
      "data.csv");
  EXPECT_EQ(t.rows(), 2u);
  EXPECT_EQ(t.header().size(), 4u);
  const auto z2 = t.column("z2_um");
  const auto s1 = t.column("s1_um");
  EXPECT_DOUBLE_EQ(z2[0], 0.125);
  EXPECT_DOUBLE_EQ(z2[1], -2.0);
  EXPECT_DOUBLE_EQ(s1[0], 3.0);
  EXPECT_DOUBLE_EQ(s1[1], 4.5);
  EXPECT_EQ(t.line_of_row(0), 4u);  // lines count comments and blanks
  EXPECT_EQ(t.line_of_row(1), 6u);
  EXPECT_TRUE(t.has_column("time_s"));
  EXPECT_FALSE(t.has_column("z1_um"));
}

TEST(CsvTable, TextInANumberCellNamesFileLineAndColumn) {
  EXPECT_EQ(error_of("a,z2_um\n1,2\n# c\n3,abc\n", "z2_um"),
            "data.csv:4: column 'z2_um' (field 2): 'abc' is not a number");
  EXPECT_EQ(error_of("z2_um\n1.5um\n", "z2_um"),
            "data.csv:2: column 'z2_um' (field 1): '1.5um' is not a number");
  EXPECT_EQ(error_of("z2_um\n0x10\n", "z2_um"),
            "data.csv:2: column 'z2_um' (field 1): '0x10' is not a number");
}

TEST(CsvTable, NaNInfinityAndEmptyCellsAreRejected) {
  EXPECT_EQ(error_of("x,y\n1,NaN\n", "y"),
            "data.csv:2: column 'y' (field 2): 'NaN' is not a finite number");
  EXPECT_EQ(error_of("x,y\n1,-inf\n", "y"),
            "data.csv:2: column 'y' (field 2): '-inf' is not a finite number");
  EXPECT_EQ(error_of("x,y\n1, \n", "y"),
            "data.csv:2: column 'y' (field 2): empty cell, expected a number");
  // A bad cell in a column nobody asks for is ignored.
  EXPECT_EQ(error_of("x,y\nabc,1\n", "y"), "no error");
}

TEST(CsvTable, StructuralErrorsNameTheLine) {
  EXPECT_EQ(error_of("x,y\n1,2\n3\n"), "data.csv:3: 1 fields, but the header (line 1) has 2");
  EXPECT_EQ(error_of("# only a comment\n\n"),
            "data.csv: no header row: the file is empty or has only comments");
  EXPECT_EQ(error_of("x,,y\n"),
            "data.csv:1: header field 2 is empty (a trailing comma?); the header names the "
            "columns, e.g. s1_um,s2_um,s3_um");
  EXPECT_EQ(error_of("y,x,y\n1,2,3\n", "y"),
            "data.csv:1: column 'y' appears twice (fields 1 and 3)");
  EXPECT_EQ(error_of("# c\nx,y\n1,2\n", "z"),
            "data.csv:2: missing column 'z' (the header has: x,y)");
}

TEST(CsvTable, RequireColumnsListsEveryMissingName) {
  const CsvTable t = CsvTable::parse("s1_um,z1_um\n", "poses.csv");
  EXPECT_EQ(t.rows(), 0u);
  try {
    t.require_columns({"s1_um", "s2_um", "z1_um", "z3_um"});
    FAIL() << "no error";
  } catch (const core::InputError& e) {
    EXPECT_STREQ(e.what(),
                 "poses.csv:1: missing columns 's2_um', 'z3_um' (the header has: s1_um,z1_um)");
  }
}

TEST(CsvTable, MissingFileNamesThePath) {
  try {
    CsvTable::load("/nonexistent/dir/poses.csv");
    FAIL() << "no error";
  } catch (const core::InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "/nonexistent/dir/poses.csv: cannot open: No such file or directory");
  }
}

TEST(CsvTable, AHeaderWiderThanTheLimitIsRefused) {
  std::string wide = "c0";
  for (std::size_t i = 1; i < CsvTable::kMaxColumns; ++i)
    wide += fmt::format(",c{}", i);
  const CsvTable t = CsvTable::parse(wide + "\n", "wide.csv");
  EXPECT_EQ(t.header().size(), 1024u);
  EXPECT_EQ(error_of(wide + ",one_more\n1\n"),
            "data.csv:1: the header has 1025 fields, more than the limit of 1024");
  EXPECT_EQ(error_of("# c\n" + std::string(1 << 20, ',') + "\n"),
            "data.csv:2: the header has 1048577 fields, more than the limit of 1024");
}

// A 64 MiB file of commas once took 3.9 GB, 32 bytes a comma, before it was refused. A row
// is now counted, not split, when read: the reader holds the text and 16 bytes a row.
class CsvTableMemory : public piezoshift::testing::TempDirTest {};

TEST_F(CsvTableMemory, ARowOfMillionsOfEmptyCellsIsRefusedAtItsLineInTheTextsMemory) {
  constexpr std::size_t kCommas = 4 << 20;
  std::string text = "t_s,measured_um\n0,1\n" + std::string(kCommas, ',') + "\n1,2\n";
  const std::size_t size = text.size();
  const std::string file = write("commas.csv", text);
  text = std::string();
  std::string message;
  const testing::HeapPeak peak;
  try {
    CsvTable::load(file);
  } catch (const core::InputError& e) {
    message = e.what();
  }
  const std::size_t bytes = peak.bytes();
  EXPECT_EQ(message, file + ":3: 4194305 fields, but the header (line 1) has 2");
  EXPECT_GE(bytes, size);              // the text, read once
  EXPECT_LT(bytes, size + (1 << 20));  // and no cell: before, 32 bytes a comma (128 MiB)
}

TEST_F(CsvTableMemory, RowsOfEmptyCellsAsWideAsTheHeaderCostNoMemoryPerCell) {
  std::string text = "c0";
  for (std::size_t i = 1; i < CsvTable::kMaxColumns; ++i)
    text += fmt::format(",c{}", i);
  text += '\n';
  constexpr std::size_t kRows = 4096;  // 4 MiB of commas
  for (std::size_t r = 0; r < kRows; ++r)
    text.append(CsvTable::kMaxColumns - 1, ',').push_back('\n');
  const std::size_t size = text.size();
  const std::string file = write("empty.csv", text);
  text = std::string();
  const testing::HeapPeak peak;
  const CsvTable t = CsvTable::load(file);
  const std::size_t bytes = peak.bytes();
  EXPECT_EQ(t.rows(), kRows);
  EXPECT_EQ(t.line_of_row(kRows - 1), kRows + 1);
  EXPECT_LT(bytes, size + 16 * kRows + (1 << 20));  // before: 32 bytes a cell (128 MiB)
  try {
    t.column("c7");
    ADD_FAILURE() << "no error";
  } catch (const core::InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              file + ":2: column 'c7' (field 8): empty cell, expected a number");
  }
}

// A valid 64 MiB file of one-cell rows once peaked at 1.39 GB (16 bytes a row, and the
// rows' vector doubling while read). Now 8 bytes a row, reserved once: the text, the rows and a
// column of 8 bytes a row, nothing more.
TEST_F(CsvTableMemory, OneCellRowsCostEightBytesEachAndAColumnEightMore) {
  constexpr std::size_t kRows = 4 << 20;
  std::string text = "z\n";
  for (std::size_t r = 0; r < kRows; ++r)
    text += "1\n";
  const std::size_t size = text.size();
  const std::string file = write("ones.csv", text);
  text = std::string();
  const testing::HeapPeak peak;
  const CsvTable t = CsvTable::load(file);
  const std::vector<double> z = t.column("z");
  const std::size_t bytes = peak.bytes();
  EXPECT_EQ(z.size(), kRows);
  EXPECT_GE(bytes, size + 16 * kRows);              // the text, the rows, the column
  EXPECT_LT(bytes, size + 16 * kRows + (1 << 20));  // before: 104 MiB, now 72 MiB
}

TEST(CsvTable, CellsAreFoundAgainInTheirRows) {
  // The first and last fields, a carriage return only at the line's end, blanks trimmed.
  const CsvTable t = CsvTable::parse("a,b,c\r\n 1 ,2,\t3\r\n4,5,6\n7,8,9", "r.csv");
  EXPECT_EQ(t.column("a"), (std::vector<double>{1, 4, 7}));
  EXPECT_EQ(t.column("b"), (std::vector<double>{2, 5, 8}));
  EXPECT_EQ(t.column("c"), (std::vector<double>{3, 6, 9}));
  EXPECT_EQ(error_of("x,y\n1\r,2\n", "x"),
            "data.csv:2: column 'x' (field 1): '1\r' is not a number");
}

TEST(CsvTable, ParseFiniteDoubleIsStrict) {
  double v = 0.0;
  EXPECT_TRUE(parse_finite_double(" 1e-3 ", v));
  EXPECT_DOUBLE_EQ(v, 1e-3);
  EXPECT_TRUE(parse_finite_double("+.5", v));
  EXPECT_DOUBLE_EQ(v, 0.5);
  EXPECT_FALSE(parse_finite_double("1,5", v));
  EXPECT_FALSE(parse_finite_double("+-1", v));
  EXPECT_FALSE(parse_finite_double("1e999", v));  // out of range
  EXPECT_FALSE(parse_finite_double("nan", v));
  EXPECT_FALSE(parse_finite_double("", v));
}

}  // namespace
}  // namespace piezoshift::io
