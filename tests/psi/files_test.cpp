#include <gtest/gtest.h>
#include <png.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/psi/analysis.hpp"
#include "piezoshift/psi/frame_set.hpp"
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

// Counts as a 16-bit gray PNG written by libpng itself with Adam7 interlacing, as cameras' and
// image tools' encoders may write them.
void write_interlaced_png16(const std::string& path, const Map& counts) {
  FILE* f = std::fopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  png_init_io(png, f);
  png_set_IHDR(png, info, static_cast<png_uint_32>(counts.width),
               static_cast<png_uint_32>(counts.height), 16, PNG_COLOR_TYPE_GRAY,
               PNG_INTERLACE_ADAM7, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  std::vector<std::vector<png_byte>> rows(static_cast<std::size_t>(counts.height));
  std::vector<png_bytep> pointers;
  for (int j = 0; j < counts.height; ++j) {
    auto& row = rows[static_cast<std::size_t>(j)];
    for (int i = 0; i < counts.width; ++i) {
      const auto c = static_cast<unsigned>(std::lround(counts.at(i, j)));
      row.push_back(static_cast<png_byte>(c >> 8));
      row.push_back(static_cast<png_byte>(c & 0xff));
    }
    pointers.push_back(row.data());
  }
  png_set_rows(png, info, pointers.data());
  png_write_png(png, info, PNG_TRANSFORM_IDENTITY, nullptr);
  png_destroy_write_struct(&png, &info);
  std::fclose(f);
}

// An Adam7-interlaced frame was decoded as if it were not (37.6 nm RMS for a 52.8 nm surface,
// analysed without complaint): it decodes to the pixels of the plain file, and four frames of a
// surface analyse to the same figures either way.
TEST(PsiFilesTest, InterlacedPngDecodesToTheSamePixelsAndAnalysis) {
  const fs::path d = temp_dir();
  const int w = 61, h = 47;  // not multiples of 8: Adam7's partial blocks at the edges
  std::vector<std::string> plain, interlaced;
  for (int k = 0; k < 4; ++k) {
    Map frame(w, h);
    for (int j = 0; j < h; ++j)
      for (int i = 0; i < w; ++i) {
        const double x = (i - w / 2.0) / (w / 2.0), y = (j - h / 2.0) / (h / 2.0);
        const double phase = 0.4 * i + 0.1 * j + 3.0 * (x * x + y * y) + k * std::numbers::pi / 2;
        frame.v[static_cast<std::size_t>(j * w + i)] =
            std::round(30000.0 + 20000.0 * std::cos(phase));
      }
    plain.push_back((d / ("p" + std::to_string(k) + ".png")).string());
    interlaced.push_back((d / ("i" + std::to_string(k) + ".png")).string());
    write_png_gray16(plain.back(), frame);
    write_interlaced_png16(interlaced.back(), frame);
  }
  const std::vector<Map> a = read_frame_set(plain), b = read_frame_set(interlaced);
  ASSERT_EQ(b.size(), 4u);
  for (std::size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(b[k].width, w);
    EXPECT_EQ(b[k].height, h);
    EXPECT_EQ(b[k].v, a[k].v) << interlaced[k];
  }
  const Mask mask = disk_mask(w, h, 20.0);
  AnalysisOptions options;
  options.phase.algorithm = Algorithm::kFourStep;
  const Analysis ra = analyze_frames(a, mask, options), rb = analyze_frames(b, mask, options);
  EXPECT_GT(ra.figures.rms, 10.0);
  EXPECT_EQ(rb.figures.rms, ra.figures.rms);
  EXPECT_EQ(rb.figures.pv, ra.figures.pv);
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

// The message of the InputError f throws ("" when it throws none).
template <class F>
std::string input_error(F&& f) {
  try {
    f();
  } catch (const core::InputError& e) {
    return e.what();
  }
  return "";
}

// 150 copies of one PNG once ended `psi analyze` in std::bad_alloc. The count is refused
// before any file is read (the paths here do not exist), the pixels after the first frame only.
TEST(FrameSetTest, CountIsRefusedBeforeAnyFileIsRead) {
  const std::vector<std::string> many(kMaxFrames + 1, "/nonexistent/f.png");
  EXPECT_EQ(input_error([&] { read_frame_set(many); }),
            "psi: 65 frames given, at most 64 are read (docs/psi.md)");
  const std::vector<std::string> two(2, "/nonexistent/f.png");
  EXPECT_EQ(input_error([&] { read_frame_set(two); }),
            "psi: 2 frame(s) given, at least 3 are needed");
}

TEST(FrameSetTest, PixelsAreBoundedOnceTheFirstFrameGivesTheSize) {
  const fs::path d = temp_dir();
  const std::string f = (d / "f.png").string();
  write_png_gray16(f, Map(10, 10, 7.0));
  // exactly at the limit: read; one pixel more: refused naming the first file, the rest unread
  std::vector<std::string> paths(10, f);
  EXPECT_EQ(read_frame_set(paths, {64, 1000}).size(), 10u);
  paths.push_back(f);
  for (std::size_t k = 1; k < paths.size(); ++k)
    paths[k] = (d / "missing.png").string();
  EXPECT_EQ(input_error([&] {
              read_frame_set(paths, {64, 1099});
            }),
            f + ": 11 frames of 10 x 10 pixels are 1100 pixels, at most 1099 are read "
                "(docs/psi.md)");
  // the default: 16 frames of 2048 x 2048 (512 MiB of doubles), not 17
  const std::string big = (d / "big.png").string();
  write_png_gray16(big, Map(kMaxPngSide, kMaxPngSide, 0.0));
  std::vector<std::string> seventeen(17, (d / "missing.png").string());
  seventeen[0] = big;
  EXPECT_EQ(input_error([&] { read_frame_set(seventeen); }),
            big +
                ": 17 frames of 2048 x 2048 pixels are 71303168 pixels, at most 67108864 are "
                "read (docs/psi.md)");
  fs::remove_all(d);
}

// Identical, blank and 1 x 1 frames carry no phase: the one check `psi analyze` and `psi
// calibrate` share refuses them (calibrate used to write step_gain = 0, converged = true).
TEST(FrameSetTest, FramesWithoutFringesAreRefusedByTheSharedCheck) {
  const auto fringes = [](int n, int size) {
    std::vector<Map> frames;
    for (int k = 0; k < n; ++k) {
      Map f(size, size);
      for (int j = 0; j < size; ++j)
        for (int i = 0; i < size; ++i)
          f.v[static_cast<std::size_t>(j * size + i)] =
              100.0 + 50.0 * std::cos(0.3 * i + 0.1 * j + k * std::numbers::pi / 2.0);
      frames.push_back(f);
    }
    return frames;
  };
  const auto check = [](const std::vector<Map>& frames) {
    const Mask mask(frames[0].width, frames[0].height, 1);
    PhaseOptions po;
    po.algorithm = Algorithm::kAia;
    return modulated_pixels(wrapped_phase(frames, mask, po), mask, AnalysisOptions{}).count();
  };
  EXPECT_EQ(check(fringes(5, 32)), 32u * 32u);
  const std::vector<Map> identical(5, fringes(1, 32)[0]);
  const std::vector<Map> blank(5, Map(32, 32, 0.0));
  const std::vector<Map> one_pixel = fringes(5, 1);
  for (const auto* frames : {&identical, &blank, &one_pixel}) {
    try {
      check(*frames);
      ADD_FAILURE() << frames->front().width << " px frames accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("too few pixels with fringe modulation"),
                std::string::npos)
          << e.what();
    }
  }
}

// A nominal step of 1e-300 rad gave a NaN gain; outside [0.05, pi - 0.05] rad it is refused, and
// a recovery that did not converge or steps that did not advance are not a calibration.
TEST(StepCalibrationTest, NominalStepRangeAndProblemsOfARecovery) {
  const std::vector<double> d{0.0, 1.6, 3.1, 4.7};
  EXPECT_THROW(calibrate_steps(d, 1e-300, 632.8), std::invalid_argument);
  EXPECT_THROW(calibrate_steps(d, 0.049, 632.8), std::invalid_argument);
  EXPECT_THROW(calibrate_steps(d, std::numbers::pi - 0.049, 632.8), std::invalid_argument);
  EXPECT_NO_THROW(calibrate_steps(d, kMinNominalStepRad, 632.8));
  StepCalibration c = calibrate_steps(d, std::numbers::pi / 2.0, 632.8);
  EXPECT_EQ(step_calibration_problem(c), "");
  c.converged = false;
  c.iterations = 200;
  EXPECT_EQ(step_calibration_problem(c), "aia did not converge in 200 iterations");
  const StepCalibration still = calibrate_steps(std::vector<double>(4, 0.0), 1.5, 632.8);
  EXPECT_EQ(step_calibration_problem(still), "step gain 0: the steps did not advance");
  const StepCalibration nan =
      calibrate_steps(std::vector<double>{0.0, 1.5, std::nan(""), 4.5}, 1.5, 632.8);
  EXPECT_EQ(step_calibration_problem(nan), "step 2 is not a number (nan)");
}

}  // namespace
}  // namespace piezoshift::psi
