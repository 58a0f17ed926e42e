// The pupil found from the frames' fringe modulation when no mask is given.
#include "piezoshift/psi/pupil_detection.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace piezoshift::psi {
namespace {

// Five frames at pi/2 steps: fringes inside `inside`, a constant background outside, Gaussian
// noise of 1 % of the mean everywhere.
std::vector<Map> frames_in(const Mask& inside, unsigned seed) {
  std::mt19937 gen(seed);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::vector<Map> frames;
  for (int k = 0; k < 5; ++k) {
    Map f(inside.width, inside.height);
    for (int j = 0; j < f.height; ++j)
      for (int i = 0; i < f.width; ++i) {
        const std::size_t p = static_cast<std::size_t>(j) * f.width + i;
        const double fringe =
            0.8 * std::cos(0.2 * i + 0.05 * j * j / 10.0 + k * std::numbers::pi / 2);
        f.v[p] = 1.0 + (inside.v[p] ? fringe : 0.0) + noise(gen);
      }
    frames.push_back(f);
  }
  return frames;
}

std::size_t differing(const Mask& a, const Mask& b) {
  std::size_t n = 0;
  for (std::size_t p = 0; p < a.size(); ++p)
    n += a.v[p] != b.v[p];
  return n;
}

TEST(PupilDetectionTest, FindsTheDiskKeepsTheObstructionOutAndFillsADeadPixel) {
  const Mask disk = disk_mask(96, 80, 30.0);
  EXPECT_EQ(differing(pupil_from_modulation(frames_in(disk, 1)).mask, disk), 0u);
  // a central obstruction (radius 8: 201 pixels, 7 % of the pupil) stays outside; a single dead
  // pixel (unmodulated) inside is a hole of 1 pixel, filled
  Mask ring = disk;
  const Mask hole = disk_mask(96, 80, 8.0);
  for (std::size_t p = 0; p < ring.size(); ++p)
    ring.v[p] = disk.v[p] && !hole.v[p];
  Mask dead = ring;
  dead.v[static_cast<std::size_t>(40 * 96 + 70)] = 0;  // inside the annulus
  const DetectedPupil d = pupil_from_modulation(frames_in(dead, 2));
  EXPECT_EQ(differing(d.mask, ring), 0u);
  EXPECT_NEAR(d.share, 1.0, 1e-12);
  // the robust maximum is the fringes' temporal std: 0.8 x (0.63 .. 0.75) for pi/2 steps
  EXPECT_GT(d.modulation_max, 0.8 * 0.63);
  EXPECT_LT(d.modulation_max, 0.8 * 0.76);
}

TEST(PupilDetectionTest, RefusesFramesWithoutFringesAndScatteredModulation) {
  const auto message = [](const std::vector<Map>& frames) {
    try {
      pupil_from_modulation(frames);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message(std::vector<Map>(5, Map(32, 32, 7.0)))
                .find("too few pixels with fringe modulation to find the pupil (0 of the 37"),
            std::string::npos);
  // noise alone: the pixels above a quarter of its 99th percentile do not form one region
  std::mt19937 gen(3);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<Map> frames(5, Map(64, 64));
  for (Map& f : frames)
    for (double& v : f.v)
      v = noise(gen);
  EXPECT_NE(message(frames).find("does not separate a pupil from the background"),
            std::string::npos)
      << message(frames);
}

}  // namespace
}  // namespace piezoshift::psi
