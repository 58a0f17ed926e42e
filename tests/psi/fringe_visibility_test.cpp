// A single frame's fringe visibility (the dashboard's live view) against frames whose visibility
// is known in closed form.
#include "piezoshift/psi/fringe_visibility.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace piezoshift::psi {
namespace {

// I = a + b cos(2 pi x / period): visibility b / a, whatever the phase.
TEST(FringeVisibilityTest, CosineFringesGiveTheirContrastAndADarkTileIsLeftOut) {
  Map f(64, 32);
  for (int j = 0; j < 32; ++j)
    for (int i = 0; i < 64; ++i)
      f.at(i, j) = i < 32 ? 1000.0 + 500.0 * std::cos(2.0 * std::numbers::pi * i / 8.0)
                          : 2.0;  // right half dark: outside the pupil
  const FringeVisibility v = fringe_visibility(f, 4095.0, 32);
  ASSERT_EQ(v.tiles.width, 2);
  ASSERT_EQ(v.tiles.height, 1);
  // The 98th and 2nd percentiles of 8 samples a period reach cos = +-1 exactly: 500 / 1000.
  EXPECT_NEAR(v.tiles.at(0, 0), 0.5, 1e-9);
  EXPECT_TRUE(std::isnan(v.tiles.at(1, 0)));
  EXPECT_EQ(v.judged, 1u);
  EXPECT_NEAR(v.median, 0.5, 1e-9);
  EXPECT_NEAR(v.p90, 0.5, 1e-9);
}

TEST(FringeVisibilityTest, AUniformFrameHasNoVisibilityAndBadTilesAreRefused) {
  const FringeVisibility v = fringe_visibility(Map(40, 40, 800.0), 4095.0, 16);
  EXPECT_EQ(v.tiles.width, 3);  // 16 + 16 + 8 px
  EXPECT_EQ(v.judged, 9u);
  EXPECT_DOUBLE_EQ(v.p90, 0.0);
  EXPECT_THROW(fringe_visibility(Map(40, 40, 800.0), 4095.0, 1), std::invalid_argument);
}

}  // namespace
}  // namespace piezoshift::psi
