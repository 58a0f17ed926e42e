// Set-up inputs of a run: setpoint profiles, the controller's TOML, atomic file replacement.
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "piezoshift/calibration/calibration_file.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/atomic_file.hpp"
#include "piezoshift/runtime/setpoint_profile.hpp"

#include "../support/temp_dir_test.hpp"

namespace piezoshift::runtime {
namespace {

namespace fs = std::filesystem;

using TempDir = piezoshift::testing::TempDirTest;

using SetpointProfileTest = TempDir;
using ControllerConfigTest = TempDir;
using AtomicFileTest = TempDir;

TEST_F(SetpointProfileTest, PiecewiseLinearBetweenRowsHeldOutside) {
  SetpointProfile p =
      SetpointProfile::load_csv(write("p.csv", "t_s,zd_um\n0.1,0\n0.2,10\n0.4,4\n"));
  EXPECT_EQ(p.at(0.0)[0], 0.0);
  EXPECT_NEAR(p.at(0.15)[1], 5.0, 1e-12);
  EXPECT_NEAR(p.at(0.3)[2], 7.0, 1e-12);
  EXPECT_EQ(p.at(9.0)[0], 4.0);
  EXPECT_NEAR(p.at(0.125)[0], 2.5, 1e-12) << "time going back re-searches";
}

TEST_F(SetpointProfileTest, ThreePointColumns) {
  SetpointProfile p =
      SetpointProfile::load_csv(write("p.csv", "t_s,zd1_um,zd2_um,zd3_um\n0,1,2,3\n1,3,2,1\n"));
  const Vec3 z = p.at(0.5);
  EXPECT_NEAR(z[0], 2.0, 1e-12);
  EXPECT_NEAR(z[1], 2.0, 1e-12);
  EXPECT_NEAR(z[2], 2.0, 1e-12);
}

TEST_F(SetpointProfileTest, RefusesOutOfStrokeAndNonIncreasingTimesWithLine) {
  const std::string a = write("a.csv", "t_s,zd_um\n0,1\n0.1,17\n");
  EXPECT_THROW(
      {
        try {
          SetpointProfile::load_csv(a);
        } catch (const core::InputError& e) {
          EXPECT_NE(std::string(e.what()).find("a.csv:3"), std::string::npos) << e.what();
          throw;
        }
      },
      core::InputError);
  const std::string b = write("b.csv", "t_s,zd_um\n0,1\n0,2\n");
  EXPECT_THROW(SetpointProfile::load_csv(b), core::InputError);
  EXPECT_THROW(SetpointProfile::step(-0.1), core::InputError);
  EXPECT_THROW(SetpointProfile::step(16.5), core::InputError);
}

TEST_F(ControllerConfigTest, ReadsGainsPolynomialAndMatrix) {
  const control::SemiClosedLoopParams p = calibration::load_calibration_file(write("c.toml", R"(
[controller]
kp = 0.5
ki = 0.25
kd = 0.0
gains_sample_time_s = 2e-3
p = [0.0, 0.0, 1.0, 0.1]
A = [[1, 0, 0], [0, 1.25, 0], [0, 0, 1.5]]
)"));
  EXPECT_EQ(p.gains.kp, 0.5);
  EXPECT_EQ(p.gains.ki, 0.25);
  EXPECT_EQ(p.gains_sample_time_s, 2e-3);
  EXPECT_EQ(p.polynomial.p1, 1.0);
  EXPECT_EQ(p.polynomial.p0, 0.1);
  EXPECT_EQ(p.matrix.a[1][1], 1.25);
}

TEST_F(ControllerConfigTest, AbsentKeysKeepThePapersValues) {
  const control::SemiClosedLoopParams p =
      calibration::load_calibration_file(write("c.toml", "[controller]\nkp = 0.7\n"));
  EXPECT_EQ(p.gains.kp, 0.7);
  EXPECT_EQ(p.gains.ki, 0.2);
  EXPECT_EQ(p.polynomial.p3, -0.0001009);
  EXPECT_EQ(p.matrix.a[2][2], -0.2980);
}

TEST_F(ControllerConfigTest, RejectsUnknownKeyAndShortPolynomial) {
  EXPECT_THROW(calibration::load_calibration_file(write("a.toml", "[controller]\nkq = 1\n")),
               core::InputError);
  try {
    calibration::load_calibration_file(write("b.toml", "[controller]\np = [1, 2, 3]\n"));
    FAIL();
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("controller.p"), std::string::npos) << e.what();
  }
}

TEST_F(ControllerConfigTest, TravelSectionIsOptionalAndRoundTrips) {
  std::optional<double> travel = 1.0;
  calibration::load_calibration_file(write("none.toml", "[controller]\nkp = 0.7\n"), &travel);
  EXPECT_FALSE(travel.has_value());
  const std::string path = write("t.toml", "");
  calibration::write_calibration_file(path, control::SemiClosedLoopParams{}, "travel", 11.0 / 3.0);
  calibration::load_calibration_file(path, &travel);
  ASSERT_TRUE(travel.has_value());
  EXPECT_EQ(*travel, 11.0 / 3.0);
  try {
    calibration::load_calibration_file(write("bad.toml", "[travel]\nz_max_um = -1\n"));
    FAIL();
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("travel.z_max_um"), std::string::npos) << e.what();
  }
}

TEST_F(AtomicFileTest, ReplacesContentAndLeavesNoTemporary) {
  const std::string path = write("cal.toml", "old\n");
  io::write_file_atomically(path, "new content\n");
  EXPECT_EQ(read_text(path), "new content\n");
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir_)) {
    (void)e;
    ++files;
  }
  EXPECT_EQ(files, 1);
}

// `calibrate` killed during its write once left ".cal.toml.tmp.PID" behind; the next write
// removes the temporaries of dead processes and leaves a live writer's alone.
TEST_F(AtomicFileTest, NextWriteRemovesTheTemporaryOfAKilledWriterOnly) {
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0)
    ::_exit(0);
  ASSERT_EQ(::waitpid(child, nullptr, 0), child);  // reaped: the PID no longer exists
  const std::string dead = write(".cal.toml.tmp." + std::to_string(child), "half");
  const std::string live = write(".cal.toml.tmp." + std::to_string(::getppid()), "busy");
  const std::string other = write(".other.toml.tmp." + std::to_string(child), "not ours");
  io::write_file_atomically(path("cal.toml"), "new\n");
  EXPECT_FALSE(fs::exists(dead));
  EXPECT_TRUE(fs::exists(live));
  EXPECT_TRUE(fs::exists(other));
  EXPECT_EQ(read_text(path("cal.toml")), "new\n");
}

// A symlink planted at the temporary's name once made the write go through it to the file it
// pointed to. The link is removed, its target left as it was, and the file written.
TEST_F(AtomicFileTest, APlantedSymlinkAtTheTemporarysNameIsNotWrittenThrough) {
  const std::string victim = write("victim.txt", "precious\n");
  const fs::path link = dir_ / (".cal.toml.tmp." + std::to_string(::getpid()));
  fs::create_symlink(victim, link);
  io::write_file_atomically(path("cal.toml"), "new\n");
  EXPECT_EQ(read_text(victim), "precious\n");
  EXPECT_EQ(read_text(path("cal.toml")), "new\n");
  EXPECT_FALSE(fs::exists(fs::symlink_status(link)));
}

TEST_F(AtomicFileTest, FailureLeavesTheOldFileIntact) {
  const std::string path = write("cal.toml", "old\n");
  EXPECT_THROW(io::write_file_atomically((dir_ / "missing" / "cal.toml").string(), "x"),
               core::InputError);
  EXPECT_EQ(read_text(path), "old\n");
}

}  // namespace
}  // namespace piezoshift::runtime
