#include "piezoshift/experiments/metrics_linearity.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace piezoshift::experiments {
namespace {

TEST(Linearity, HandCalculatedZeroEndAndBestFit) {
  const std::vector<double> x{0, 1, 2, 3, 4};
  const std::vector<double> y{0, 1.01, 2.03, 3.02, 4.00};
  // By hand. Base B = 4.00 - 0 = 4 um.
  // Zero-end line through (0, 0) and (4, 4): y = x; deviations 0, .01, .03, .02, 0;
  //   max .03 um -> 100 * .03 / 4 = 0.75 %.
  // Best fit: xbar = 2, ybar = 10.06 / 5 = 2.012, Sxx = 10,
  //   Sxy = (-2)(-2.012) + (-1)(-1.002) + 0 + (1)(1.008) + (2)(1.988) = 10.01,
  //   b = 1.001, a = 2.012 - 2.002 = 0.010;
  //   residuals -0.010, -0.001, 0.018, 0.007, -0.014; max .018 -> 100 * .018 / 4 = 0.45 %.
  const LinearityMetrics m = linearity_metrics(x, y);
  EXPECT_EQ(m.n, 5u);
  EXPECT_NEAR(m.span_um, 4.0, 1e-15);
  EXPECT_NEAR(m.zero_end_slope, 1.0, 1e-15);
  EXPECT_NEAR(m.zero_end_intercept_um, 0.0, 1e-15);
  EXPECT_NEAR(m.max_deviation_zero_end_um, 0.03, 1e-12);
  EXPECT_NEAR(m.linearity_zero_end_pct, 0.75, 1e-10);
  EXPECT_NEAR(m.best_fit_slope, 1.001, 1e-12);
  EXPECT_NEAR(m.best_fit_intercept_um, 0.010, 1e-12);
  EXPECT_NEAR(m.deviation_best_fit_um[2], 0.018, 1e-12);
  EXPECT_NEAR(m.deviation_best_fit_um[4], -0.014, 1e-12);
  EXPECT_NEAR(m.linearity_best_fit_pct, 0.45, 1e-10);
  EXPECT_NEAR(m.deviation_zero_end_um[0], 0.0, 0.0);
  EXPECT_NEAR(m.deviation_zero_end_um[4], 0.0, 1e-15);
}

TEST(Linearity, OffsetAndDecreasingSweepUseTheMeasuredSpanAsBase) {
  // Sweep from 11 down to 1 um with an offset: zero-end line through (11, 11.5), (1, 1.5);
  // slope 1, the middle point (6, 6.6) deviates by +0.1 um; base |1.5 - 11.5| = 10 -> 1 %.
  const std::vector<double> x{11, 6, 1};
  const std::vector<double> y{11.5, 6.6, 1.5};
  const LinearityMetrics m = linearity_metrics(x, y);
  EXPECT_NEAR(m.span_um, -10.0, 1e-12);
  EXPECT_NEAR(m.linearity_zero_end_pct, 1.0, 1e-10);
  // Best fit: xbar 6, ybar 19.6/3, b = Sxy/Sxx = (5*4.966.. ) -> residuals +-1/30 and 2/30:
  //   r = y - ybar - (x - xbar) = (-1/30, +2/30, -1/30) um -> 100 * (1/15) / 10 = 0.6667 %.
  EXPECT_NEAR(m.linearity_best_fit_pct, 100.0 * (2.0 / 30.0) / 10.0, 1e-10);
}

TEST(Linearity, RejectsDegenerateData) {
  const std::vector<double> two{0, 1};
  EXPECT_THROW(linearity_metrics(two, two), MetricsError);
  const std::vector<double> x{1, 2, 1}, y{0, 1, 2};
  EXPECT_THROW(linearity_metrics(x, y), MetricsError);  // x0 == x_last
  const std::vector<double> x2{0, 1, 2}, flat{3, 3.1, 3};
  EXPECT_THROW(linearity_metrics(x2, flat), MetricsError);  // zero base
  const std::vector<double> y3{0, 1};
  EXPECT_THROW(linearity_metrics(x2, y3), MetricsError);
}

}  // namespace
}  // namespace piezoshift::experiments
