// The improved calibration's verdict on its loop's rate (calibration/rate_verdict.hpp): a plate
// mode near a multiple of the 1 kHz tick names itself, the step it allows and the rate that
// meets 5 ms; a mode far from them gives no verdict.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "piezoshift/calibration/rate_verdict.hpp"

namespace piezoshift::calibration {
namespace {

TEST(RateVerdict, TheStepIsTheDelayAndTheShapersSpanAsMeasuredAt1kHz) {
  // docs/compare.md, seed 1 at 1 kHz: 4 ms (default, 3 taps), 7 ms (payload, 6 taps), 6 ms
  // (contact-spread, 5 taps); the delay is 2 ticks on each.
  EXPECT_NEAR(shaped_phase_step_s(1419.0, 1000.0, 2), 4e-3, 1e-12);
  EXPECT_NEAR(shaped_phase_step_s(1175.0, 1000.0, 2), 7e-3, 1e-12);
  EXPECT_NEAR(shaped_phase_step_s(1190.0, 1000.0, 2), 6e-3, 1e-12);
  // 1024 Hz folds to 24 Hz: positive taps that null it span ceil(pi / theta) = 21 ticks.
  EXPECT_NEAR(shaped_phase_step_s(1024.0, 1000.0, 2), 23e-3, 1e-12);
  // On a multiple of the rate nothing nulls it; without a mode there is nothing to say.
  EXPECT_TRUE(std::isinf(shaped_phase_step_s(2000.0, 1000.0, 2)));
  EXPECT_TRUE(std::isnan(shaped_phase_step_s(0.0, 1000.0, 2)));
  // At 10 kHz one 1 ms exposure is added (measured 1.6 to 1.8 ms): 1419 Hz, a 7-tap average.
  EXPECT_NEAR(shaped_phase_step_s(1419.0, 10000.0, 2), 1.8e-3, 1e-12);
}

TEST(RateVerdict, AModeNearTheTicksMultiplesIsNamedWithItsStepAndAFasterRate) {
  const RateVerdict v = judge_loop_rate(1024.0, 1000.0, 2);
  ASSERT_TRUE(v.mode_is_the_limit);
  EXPECT_DOUBLE_EQ(v.folded_Hz, 24.0);
  EXPECT_NEAR(v.step_s, 23e-3, 1e-12);
  // At 2 kHz the fold is 976 Hz, three taps: 2 + 2 ticks of 0.5 ms and one exposure.
  EXPECT_DOUBLE_EQ(v.faster_rate_Hz, 2000.0);
  EXPECT_NEAR(v.faster_step_s, 3e-3, 1e-12);
  EXPECT_EQ(v.text(),
            "the plate's mode at 1024 Hz folds to 24 Hz at the 1 kHz loop rate: the lambda/8 "
            "step it allows there is 23 ms (target 5 ms); at 2 kHz it is 3.0 ms");
  // A fold that needs six taps (payload's 1175 Hz) is named too, with 7 ms.
  const RateVerdict p = judge_loop_rate(1175.0, 1000.0, 2);
  EXPECT_TRUE(p.mode_is_the_limit);
  EXPECT_NEAR(p.step_s, 7e-3, 1e-12);
  EXPECT_GT(p.faster_rate_Hz, 1000.0);
  EXPECT_LE(p.faster_step_s, 5e-3);
}

TEST(RateVerdict, AModeFarFromTheTicksMultiplesGivesNoVerdict) {
  for (const double mode_Hz : {1419.0, 1583.0, 1500.0}) {
    const RateVerdict v = judge_loop_rate(mode_Hz, 1000.0, 2);
    EXPECT_FALSE(v.mode_is_the_limit) << mode_Hz;
    EXPECT_LE(v.step_s, 5e-3) << mode_Hz;
    EXPECT_EQ(v.text(), "") << mode_Hz;
    EXPECT_DOUBLE_EQ(v.faster_rate_Hz, 0.0) << mode_Hz;
  }
  const RateVerdict none = judge_loop_rate(0.0, 1000.0, 2);  // no mode identified
  EXPECT_FALSE(none.mode_is_the_limit);
  EXPECT_EQ(none.text(), "");
}

}  // namespace
}  // namespace piezoshift::calibration
