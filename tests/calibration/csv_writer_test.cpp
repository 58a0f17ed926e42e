#include "piezoshift/io/csv_writer.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/csv_table.hpp"

namespace piezoshift::io {
namespace {

std::filesystem::path temp_file(const std::string& name) {
  const auto dir = std::filesystem::path(testing::TempDir()) / "piezoshift_csv_writer";
  std::filesystem::create_directories(dir);
  return dir / name;
}

TEST(CsvWriter, WritesFixedDecimalsThatCsvTableReadsBack) {
  const auto path = temp_file("log.csv");
  {
    CsvWriter w(path.string(), {"time_s", "z_um"}, 4);
    w.comment("seed 42\nsecond line");
    w.row({0.001, 1.23456});
    w.row({0.002, -0.00004});
    w.flush();
    EXPECT_EQ(w.rows_written(), 2u);
    EXPECT_THROW(w.row({1.0}), std::invalid_argument);
    w.close();
  }
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), "time_s,z_um\n# seed 42 second line\n0.0010,1.2346\n0.0020,-0.0000\n");
  const CsvTable t = CsvTable::load(path.string());
  EXPECT_DOUBLE_EQ(t.column("z_um")[0], 1.2346);
}

TEST(CsvWriter, NonFiniteValuesAreWrittenAndThenRefusedByTheReader) {
  const auto path = temp_file("nan.csv");
  {
    CsvWriter w(path.string(), {"z_um"});
    w.row({NAN});
  }
  const CsvTable t = CsvTable::load(path.string());
  try {
    t.column("z_um");
    FAIL() << "no error";
  } catch (const core::InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              path.string() + ":2: column 'z_um' (field 1): 'nan' is not a finite number");
  }
}

TEST(CsvWriter, UncreatableFileIsAnInputErrorNamingIt) {
  EXPECT_THROW(CsvWriter("/nonexistent/dir/log.csv", {"z_um"}), core::InputError);
}

}  // namespace
}  // namespace piezoshift::io
