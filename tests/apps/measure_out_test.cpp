// A file appearing in an empty --out while a measurement ran once made the finished
// measurement be discarded (exit 2). Where it goes now: --out while it is free (absent, or an
// empty folder), else the first free sibling --out.1 .. --out.99, never into or over what appeared.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "measure_report.hpp"
#include "temp_dir_test.hpp"

namespace piezoshift::app {
namespace {

namespace fs = std::filesystem;

using MeasureOut = testing::TempDirTest;

TEST_F(MeasureOut, AFinishedMeasurementGoesBesideAnOutThatIsNoLongerFree) {
  const fs::path out = path("m");
  EXPECT_EQ(measurement_destination(out), out);  // absent
  fs::create_directory(out);
  EXPECT_EQ(measurement_destination(out), out);  // an empty folder gives way
  write("m/appeared.txt", "not the measurement's");
  EXPECT_EQ(measurement_destination(out), fs::path(path("m.1")));
  EXPECT_EQ(measurement_destination(path("m") + "/"), fs::path(path("m.1")));  // DIR/ names DIR
  fs::create_directory(path("m.1"));  // taken too, even empty: only --out itself gives way
  write("m.2", "a file");
  EXPECT_EQ(measurement_destination(out), fs::path(path("m.3")));
  fs::create_symlink(path("elsewhere"), path("m.3"));  // a dangling link is taken, not followed
  EXPECT_EQ(measurement_destination(out), fs::path(path("m.4")));
  for (int k = 4; k < 100; ++k)
    fs::create_directory(path("m." + std::to_string(k)));
  EXPECT_EQ(measurement_destination(out), std::nullopt);
  // A file where the folder was to be is not free either.
  write("f", "");
  EXPECT_EQ(measurement_destination(path("f")), fs::path(path("f.1")));
}

}  // namespace
}  // namespace piezoshift::app
