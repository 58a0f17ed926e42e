#include "piezoshift/calibration/poly_fit.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <vector>

#include "gaussian_noise.hpp"

namespace piezoshift::calibration {
namespace {

const control::CubicPolynomial kPaperP;  // p3 = -0.0001009, p2 = 0.000389, p1 = 1.014, p0 = 0.2914

// The paper's third calibration step: 10 or more equally spaced displacements over the travel;
// here the measured displacements 0, 1, ..., 11 um and the commands that produced them.
std::vector<double> sweep() {
  std::vector<double> m;
  for (int k = 0; k <= 11; ++k)
    m.push_back(k);
  return m;
}

TEST(PolyFit, RecoversPaperCoefficientsFromExactData) {
  const std::vector<double> m = sweep();
  std::vector<double> c;
  for (double x : m)
    c.push_back(kPaperP(x));
  const PolyFitResult r = fit_cubic_polynomial(m, c);
  EXPECT_EQ(r.points, 12u);
  EXPECT_NEAR(r.p.p3, kPaperP.p3, 1e-9);
  EXPECT_NEAR(r.p.p2, kPaperP.p2, 1e-9);
  EXPECT_NEAR(r.p.p1, kPaperP.p1, 1e-9);
  EXPECT_NEAR(r.p.p0, kPaperP.p0, 1e-9);
  EXPECT_LT(r.rms_residual_um, 1e-12);
  // Centring and scaling m to [-1, 1] is what keeps the design well conditioned.
  EXPECT_LT(r.condition_number, 10.0);
  EXPECT_GT(r.condition_number_unscaled, 1e3);
}

TEST(PolyFit, RecoversCoefficientsOffOrigin) {
  std::vector<double> m, c;
  for (int k = 0; k < 15; ++k) {
    m.push_back(-0.3 + 0.77 * k);
    c.push_back(kPaperP(m.back()));
  }
  const PolyFitResult r = fit_cubic_polynomial(m, c);
  EXPECT_NEAR(r.p.p3, kPaperP.p3, 1e-9);
  EXPECT_NEAR(r.p.p0, kPaperP.p0, 1e-9);
}

TEST(PolyFit, NoisyDataWithinFiveStandardErrors) {
  std::vector<double> m;
  for (int rep = 0; rep < 4; ++rep)
    for (double x : sweep())
      m.push_back(x);
  const double sigma = 0.001;  // 1 nm on the command-side equation
  test::GaussianNoise noise(7, sigma);
  std::vector<double> c;
  for (double x : m)
    c.push_back(kPaperP(x) + noise());
  const PolyFitResult r = fit_cubic_polynomial(m, c);
  // se(p_k) = sigma sqrt(((V^T V)^-1)_kk), V = [m^3 m^2 m 1] (ordinary least squares).
  Eigen::MatrixXd v(static_cast<Eigen::Index>(m.size()), 4);
  for (Eigen::Index i = 0; i < v.rows(); ++i) {
    const double x = m[static_cast<std::size_t>(i)];
    v.row(i) << x * x * x, x * x, x, 1.0;
  }
  const Eigen::Matrix4d cov = (v.transpose() * v).inverse();
  const double fitted[] = {r.p.p3, r.p.p2, r.p.p1, r.p.p0};
  const double truth[] = {kPaperP.p3, kPaperP.p2, kPaperP.p1, kPaperP.p0};
  for (int k = 0; k < 4; ++k) {
    const double se = sigma * std::sqrt(cov(k, k));
    EXPECT_NEAR(fitted[k], truth[k], 5.0 * se) << "p" << 3 - k << " se " << se;
  }
  EXPECT_NEAR(r.rms_residual_um, sigma * std::sqrt(44.0 / 48.0), 0.25 * sigma);
  // The fitted curve stays within 1 nm of the truth over the travel.
  for (double x = 0.0; x <= 11.0; x += 0.25)
    EXPECT_NEAR(r.p(x), kPaperP(x), 0.001) << x;
}

TEST(PolyFit, DetectsRankDeficientDesign) {
  // Five points, but only three distinct displacements: a cubic is not determined.
  const std::vector<double> m{0, 0, 5, 5, 10}, c{0.3, 0.3, 5.4, 5.4, 10.4};
  try {
    fit_cubic_polynomial(m, c);
    FAIL() << "no error";
  } catch (const FitError& e) {
    EXPECT_NE(std::string(e.what()).find("rank-deficient: 3 distinct"), std::string::npos)
        << e.what();
  }
  const std::vector<double> same(6, 2.0);
  EXPECT_THROW(fit_cubic_polynomial(same, same), FitError);
}

TEST(PolyFit, RejectsTooFewPointsAndNonFiniteValues) {
  const std::vector<double> m{0, 1, 2, 3}, c{0, 1, 2, 3};
  try {
    fit_cubic_polynomial(m, c);
    FAIL() << "no error";
  } catch (const FitError& e) {
    EXPECT_NE(std::string(e.what()).find("4 points; at least 5"), std::string::npos) << e.what();
  }
  const std::vector<double> m5{0, 1, 2, 3, INFINITY}, c5{0, 1, 2, 3, 4};
  EXPECT_THROW(fit_cubic_polynomial(m5, c5), FitError);
}

}  // namespace
}  // namespace piezoshift::calibration
