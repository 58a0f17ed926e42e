#include "piezoshift/control/cubic_polynomial.hpp"

#include <gtest/gtest.h>

namespace piezoshift::control {
namespace {

TEST(CubicPolynomial, PaperCoefficientsEvaluateByHand) {
  const CubicPolynomial p;  // paper defaults
  // -0.0001009*125 + 0.000389*25 + 1.014*5 + 0.2914 = 5.3585125
  EXPECT_NEAR(p(5.0), 5.3585125, 1e-12);
  EXPECT_NEAR(p(0.0), 0.2914, 1e-15);
  // 3*(-0.0001009)*25 + 2*0.000389*5 + 1.014 = 1.0103225
  EXPECT_NEAR(p.derivative(5.0), 1.0103225, 1e-12);
}

TEST(CubicPolynomial, InverseRoundTripsOverTheTravel) {
  const CubicPolynomial p;
  for (double x = 0.0; x <= 12.0; x += 0.37) {
    const InverseResult r = inverse(p, p(x), -1.0, 16.0);
    ASSERT_EQ(r.status, InverseStatus::kOk);
    EXPECT_NEAR(r.x, x, 1e-10);
  }
}

TEST(CubicPolynomial, InverseOfDecreasingPolynomial) {
  const CubicPolynomial p{0.0, 0.0, -2.0, 1.0};  // 1 - 2x
  const InverseResult r = inverse(p, -3.0, 0.0, 5.0);
  ASSERT_EQ(r.status, InverseStatus::kOk);
  EXPECT_NEAR(r.x, 2.0, 1e-12);
}

TEST(CubicPolynomial, InverseRejectsNonMonotonicIntervalAndOutOfRange) {
  const CubicPolynomial wiggle{1.0, 0.0, -3.0, 0.0};  // x^3 - 3x, turns at x = +-1
  EXPECT_EQ(inverse(wiggle, 0.5, -2.0, 2.0).status, InverseStatus::kNotMonotonic);
  EXPECT_EQ(inverse(wiggle, 5.0, 1.5, 3.0).status, InverseStatus::kOk);
  // vertex of p' inside the interval, p' positive at both ends but negative at the vertex
  const CubicPolynomial dip{0.0, 0.0, 1.0, 0.0};
  EXPECT_EQ(inverse(dip, 100.0, 0.0, 1.0).status, InverseStatus::kOutOfRange);
  EXPECT_EQ(inverse(dip, 0.5, 1.0, 0.0).status, InverseStatus::kBadInterval);
}

}  // namespace
}  // namespace piezoshift::control
