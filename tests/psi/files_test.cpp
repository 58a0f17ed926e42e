#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/psi/npy.hpp"
#include "piezoshift/psi/png_image.hpp"
#include "piezoshift/psi/step_calibration.hpp"

namespace piezoshift::psi {
namespace {

namespace fs = std::filesystem;

fs::path temp_dir() {
  const fs::path d =
      fs::temp_directory_path() /
      ("piezoshift_psi_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
       ::testing::UnitTest::GetInstance()->current_test_info()->name());
  fs::create_directories(d);
  return d;
}

TEST(PsiFilesTest, NpyRoundTripKeepsNanAndShape) {
  const fs::path d = temp_dir();
  Map m(3, 2);
  m.v = {1.5, -2.0, std::nan(""), 4.0, 1e-300, 6.0};
  write_npy((d / "a.npy").string(), m);
  const auto size = fs::file_size(d / "a.npy");
  EXPECT_EQ(size, 128u + 6 * 8);  // 128-byte header, then the data
  const Map r = read_npy((d / "a.npy").string());
  EXPECT_EQ(r.width, 3);
  EXPECT_EQ(r.height, 2);
  EXPECT_TRUE(std::isnan(r.v[2]));
  EXPECT_EQ(r.v[4], 1e-300);
  EXPECT_EQ(r.v[5], 6.0);
  fs::remove_all(d);
}

TEST(PsiFilesTest, Png16RoundTripAndBadFilesNameThemselves) {
  const fs::path d = temp_dir();
  Map m(5, 4);
  for (std::size_t p = 0; p < m.size(); ++p)
    m.v[p] = static_cast<double>(p * 3000);
  write_png_gray16((d / "f.png").string(), m);
  const GrayImage g = read_png_gray((d / "f.png").string());
  EXPECT_EQ(g.bit_depth, 16);
  EXPECT_EQ(g.counts.width, 5);
  EXPECT_EQ(g.counts.v, m.v);
  Mask mask = disk_mask(9, 9, 3.0);
  write_mask_png((d / "m.png").string(), mask);
  EXPECT_EQ(read_mask_png((d / "m.png").string()).v, mask.v);
  std::ofstream((d / "bad.png").string()) << "not a png";
  try {
    read_png_gray((d / "bad.png").string());
    FAIL();
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.png"), std::string::npos);
  }
  EXPECT_THROW(read_png_gray((d / "missing.png").string()), core::InputError);
  fs::remove_all(d);
}

TEST(StepCalibrationTest, GainAndNonlinearityOfKnownSteps) {
  const double s = 1.5707963267948966;
  std::vector<double> d;
  for (int k = 0; k < 5; ++k)
    d.push_back(1.02 * s * k);
  const StepCalibration c = calibrate_steps(d, s, 632.8);
  EXPECT_NEAR(c.step_gain, 1.02, 1e-12);
  EXPECT_NEAR(c.nonlinearity_pct, 0.0, 1e-9);
  EXPECT_NEAR(c.steps_nm[1], 1.02 * 632.8 / 8.0, 1e-9);
  // a quadratic: delta = s k + q (s k)^2
  d.clear();
  for (int k = 0; k < 5; ++k)
    d.push_back(s * k + 0.01 * (s * k) * (s * k));
  EXPECT_NEAR(calibrate_steps(d, s, 632.8).quadratic_per_rad, 0.01, 1e-9);
  const std::string toml = format_step_calibration_toml(c);
  EXPECT_NE(toml.find("[psi_calibration]"), std::string::npos);
  EXPECT_NE(toml.find("step_gain = 1.02"), std::string::npos);
}

}  // namespace
}  // namespace piezoshift::psi
