#include "piezoshift/psi/unwrap.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace piezoshift::psi {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(UnwrapTest, MaskedTwentyFringeSurfaceUnwrapsWithoutTwoPiErrors) {
  // 20 fringes (40 pi) of tilt plus 3 fringes of defocus over a 256 px disk with a central
  // obstruction and a cut-out square: every valid pixel must come back as truth + one constant.
  constexpr int n = 256;
  Mask mask = disk_mask(n, n, 120.0);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double r = std::hypot(i - 127.5, j - 127.5);
      if (r < 25.0 || (i > 170 && i < 200 && j > 60 && j < 90))
        mask.v[static_cast<std::size_t>(j) * n + i] = 0;
    }
  Map truth(n, n), wrapped(n, n, std::nan(""));
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double x = (i - 127.5) / 120.0, y = (127.5 - j) / 120.0;
      truth.at(i, j) = 20.0 * kPi * x + 6.0 * kPi * (x * x + y * y) + 0.7 * y;
      if (mask.v[static_cast<std::size_t>(j) * n + i])
        wrapped.at(i, j) = std::remainder(truth.at(i, j), 2.0 * kPi);
    }
  const Map u = unwrap_phase(wrapped, mask);
  double offset = std::nan("");
  int bad = 0;
  std::size_t valid = 0;
  for (std::size_t p = 0; p < mask.size(); ++p) {
    if (!mask.v[p]) {
      EXPECT_TRUE(std::isnan(u.v[p]));
      continue;
    }
    ++valid;
    const double d = u.v[p] - truth.v[p];
    if (std::isnan(offset))
      offset = d;
    if (std::fabs(d - offset) > 1e-9)
      ++bad;
  }
  EXPECT_GT(valid, 40000u);
  EXPECT_EQ(bad, 0);
  EXPECT_NEAR(std::remainder(offset, 2.0 * kPi), 0.0, 1e-9);
}

TEST(UnwrapTest, SeparateIslandsEachUnwrap) {
  constexpr int n = 64;
  Mask mask(n, n, 0);
  Map truth(n, n), wrapped(n, n, std::nan(""));
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const std::size_t p = static_cast<std::size_t>(j) * n + i;
      truth.v[p] = 0.9 * i + 0.3 * j;
      if (i < 28 || i > 36) {
        mask.v[p] = 1;
        wrapped.v[p] = std::remainder(truth.v[p], 2.0 * kPi);
      }
    }
  const Map u = unwrap_phase(wrapped, mask);
  // within each island the differences are the truth's
  EXPECT_NEAR(u.at(20, 10) - u.at(0, 0), truth.at(20, 10) - truth.at(0, 0), 1e-9);
  EXPECT_NEAR(u.at(63, 63) - u.at(40, 0), truth.at(63, 63) - truth.at(40, 0), 1e-9);
}

}  // namespace
}  // namespace piezoshift::psi
