#include "piezoshift/io/csv_table.hpp"

#include <gtest/gtest.h>

#include <string>

#include "piezoshift/core/input_error.hpp"

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
