#include "piezoshift/experiments/metrics_repeatability.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace piezoshift::experiments {
namespace {

TEST(Repeatability, HandCalculatedEq9) {
  // Deviations from the mean 10.000 um: 0, +2, -2, +1, -1 nm; sum of squares 10 nm^2;
  // / (n - 1) = 4 -> 2.5 nm^2 -> e_R = sqrt(2.5) = 1.5811388 nm.
  const std::vector<double> z{10.000, 10.002, 9.998, 10.001, 9.999};
  const RepeatabilityMetrics r = repeatability_metrics(z);
  EXPECT_EQ(r.n, 5u);
  EXPECT_NEAR(r.mean_um, 10.0, 1e-14);
  EXPECT_NEAR(r.repeatability_nm, 1.5811388300841898, 1e-9);
  EXPECT_NEAR(r.repeatability_um, 1.5811388300841898e-3, 1e-12);
  EXPECT_DOUBLE_EQ(r.min_um, 9.998);
  EXPECT_DOUBLE_EQ(r.max_um, 10.002);
}

TEST(Repeatability, TwoValuesDivideByOne) {
  // n = 2: e_R = |a - b| / sqrt(2); 5.003 and 4.999 -> 4 nm / sqrt 2 = 2.828427 nm.
  const std::vector<double> z{5.003, 4.999};
  EXPECT_NEAR(repeatability_metrics(z).repeatability_nm, 4.0 / std::sqrt(2.0), 1e-9);
}

TEST(Repeatability, RejectsFewerThanTwoAndNonFinite) {
  const std::vector<double> one{1.0};
  EXPECT_THROW(repeatability_metrics(one), MetricsError);
  const std::vector<double> bad{1.0, NAN};
  EXPECT_THROW(repeatability_metrics(bad), MetricsError);
}

// Finite values whose squares overflow once gave e_R = inf; now a failure naming the range.
TEST(Repeatability, ValuesThatOverflowEq9AreRefused) {
  const std::vector<double> huge{1e308, -1e308};
  try {
    repeatability_metrics(huge);
    ADD_FAILURE() << "no error";
  } catch (const MetricsError& e) {
    EXPECT_NE(std::string(e.what()).find("overflow Eq. 9"), std::string::npos) << e.what();
  }
  const std::vector<double> both{1e308, 1e308};  // the sum overflows, the spread does not
  EXPECT_THROW(repeatability_metrics(both), MetricsError);
}

}  // namespace
}  // namespace piezoshift::experiments
