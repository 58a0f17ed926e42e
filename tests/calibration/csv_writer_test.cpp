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

// A record replaced atomically: the old file stays whole until close() writes every row at once
// (`calibrate --controller improved` once left excitation.csv half written when stopped);
// a writer dropped without close() leaves the old file and no temporary.
TEST(CsvWriter, ReplaceAtomicallyKeepsTheOldFileUntilClose) {
  const auto path = temp_file("record.csv");
  std::filesystem::remove(path);
  std::ofstream(path) << "old\n";
  const auto slurp = [&path] {
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  };
  {
    CsvWriter w(path.string(), {"t_s", "z_um"}, 2, CsvWriter::Mode::kReplaceAtomically);
    w.comment("rows = 2");
    w.row({0.0, 1.0});
    w.flush();
    EXPECT_EQ(slurp(), "old\n");
    w.row({0.5, -1.0});
    EXPECT_EQ(w.rows_written(), 2u);
  }  // no close(): nothing replaced
  EXPECT_EQ(slurp(), "old\n");
  CsvWriter w(path.string(), {"t_s", "z_um"}, 2, CsvWriter::Mode::kReplaceAtomically);
  w.row({0.0, 1.0});
  EXPECT_EQ(slurp(), "old\n");
  w.row({0.5, -1.0});
  w.close();
  EXPECT_EQ(slurp(), "t_s,z_um\n0.00,1.00\n0.50,-1.00\n");
  EXPECT_THROW(w.row({1.0, 2.0}), std::logic_error);
  for (const auto& e : std::filesystem::directory_iterator(path.parent_path()))
    EXPECT_EQ(e.path().filename().string().find(".record.csv.tmp"), std::string::npos) << e.path();
  EXPECT_THROW(
      {
        CsvWriter bad("/nonexistent/dir/r.csv", {"z_um"}, 6, CsvWriter::Mode::kReplaceAtomically);
        bad.close();
      },
      core::InputError);
}

}  // namespace
}  // namespace piezoshift::io
