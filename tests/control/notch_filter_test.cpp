#include "piezoshift/control/notch_filter.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

namespace piezoshift::control {
namespace {

// The steady amplitude of a sine at f_Hz through the filter, sampled at T.
double amplitude_through(NotchFilter f, double f_Hz, double T) {
  double peak = 0.0;
  for (int k = 0; k < 4000; ++k) {
    const double y = f.update(std::sin(2.0 * std::numbers::pi * f_Hz * T * k));
    if (k >= 3000)
      peak = std::max(peak, std::fabs(y));
  }
  return peak;
}

TEST(NotchFilter, RemovesItsFoldedFrequencyAndPassesDcAndTheLoopsBand) {
  const double T = 1e-3;
  // contact-spread's piston mode (1190 Hz) as a 1 kHz loop sees it: 190 Hz.
  const NotchFilter notch(NotchParams{1190.0, 0.85}, T);
  ASSERT_TRUE(notch.active());
  EXPECT_LT(amplitude_through(notch, 190.0, T), 1e-6);
  EXPECT_NEAR(amplitude_through(notch, 10.0, T), 1.0, 0.01);
  NotchFilter dc = notch;
  double y = 0.0;
  for (int k = 0; k < 200; ++k)
    y = dc.update(3.5);
  EXPECT_NEAR(y, 3.5, 1e-12);  // starts at rest on its first sample: no transient
}

TEST(NotchFilter, WithoutAModePassesThrough) {
  NotchFilter none(NotchParams{}, 1e-3);
  EXPECT_FALSE(none.active());
  EXPECT_EQ(none.update(1.25), 1.25);
  NotchFilter at_dc(NotchParams{1000.0, 0.85}, 1e-3);  // folds to 0 Hz: would remove DC
  EXPECT_FALSE(at_dc.active());
}

}  // namespace
}  // namespace piezoshift::control
