#include "piezoshift/calibration/matrix_fit.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <vector>

#include "gaussian_noise.hpp"

namespace piezoshift::calibration {
namespace {

using control::Vec3;

Eigen::Matrix3d to_eigen(const control::Mat3& m) {
  Eigen::Matrix3d e;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      e(r, c) = m[r][c];
  return e;
}

// The paper's calibration procedure (Section 3, second step): each actuator moved on its own
// to amplitudes 1..10 um, `repeats` times; the points then sit at Z = A^-1 S.
struct Poses {
  std::vector<Vec3> s, z;
};
Poses individual_moves(const Eigen::Matrix3d& a, int repeats) {
  Poses p;
  const Eigen::Matrix3d a_inv = a.inverse();
  for (int rep = 0; rep < repeats; ++rep) {
    for (int act = 0; act < 3; ++act) {
      for (int amp = 1; amp <= 10; ++amp) {
        Eigen::Vector3d s = Eigen::Vector3d::Zero();
        s(act) = amp;
        const Eigen::Vector3d z = a_inv * s;
        p.s.push_back({s(0), s(1), s(2)});
        p.z.push_back({z(0), z(1), z(2)});
      }
    }
  }
  return p;
}

const Eigen::Matrix3d kPaperA = to_eigen(control::TransmissionMatrix{}.a);

TEST(MatrixFit, RecoversPaperMatrixFromExactData) {
  const Poses p = individual_moves(kPaperA, 1);
  const MatrixFitResult r = fit_transmission_matrix(p.s, p.z);
  EXPECT_EQ(r.poses, 30u);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      EXPECT_NEAR(r.a.a[i][j], kPaperA(i, j), 1e-9) << i << "," << j;
  EXPECT_LT(r.rms_residual_um, 1e-12);
  // cond(A) of the paper's matrix, from its singular values (computed independently here).
  const Eigen::Vector3d sv = Eigen::JacobiSVD<Eigen::Matrix3d>(kPaperA).singularValues();
  EXPECT_NEAR(r.condition_number, sv(0) / sv(2), 1e-9);
  // Z = A^-1 S with S on the axes, so cond(Z) = cond(A^-1) = cond(A).
  EXPECT_NEAR(r.design_condition_number, sv(0) / sv(2), 1e-9);
}

TEST(MatrixFit, RecoversPaperMatrixFromNoisyDataWithinFiveStandardErrors) {
  Poses p = individual_moves(kPaperA, 3);         // 90 poses
  const double sigma_s = 0.002, sigma_z = 0.002;  // 2 nm on the SGS reading and on the XL-80
  test::GaussianNoise ns(42, sigma_s), nz(4242, sigma_z);
  Eigen::MatrixXd z(static_cast<Eigen::Index>(p.z.size()), 3);
  for (std::size_t i = 0; i < p.s.size(); ++i) {
    for (int j = 0; j < 3; ++j) {
      p.s[i][j] += ns();
      p.z[i][j] += nz();
      z(static_cast<Eigen::Index>(i), j) = p.z[i][j];
    }
  }
  const MatrixFitResult r = fit_transmission_matrix(p.s, p.z);
  // Row j of A solves s_j ~ Z a_j; the noise in one equation is s-noise plus a_j . z-noise, so
  // sigma_j^2 = sigma_s^2 + |a_j|^2 sigma_z^2 and se(a_jk) = sigma_j sqrt(((Z^T Z)^-1)_kk).
  const Eigen::Matrix3d cov = (z.transpose() * z).inverse();
  for (int j = 0; j < 3; ++j) {
    const double sigma_j =
        std::sqrt(sigma_s * sigma_s + kPaperA.row(j).squaredNorm() * sigma_z * sigma_z);
    for (int k = 0; k < 3; ++k) {
      const double se = sigma_j * std::sqrt(cov(k, k));
      EXPECT_NEAR(r.a.a[j][k], kPaperA(j, k), 5.0 * se) << j << "," << k << " se " << se;
      EXPECT_LT(se, 2e-4);  // the stated tolerance is tight: the fit really averages
    }
    // The rms residual estimates sigma_j (n - 3 degrees of freedom of n = 90).
    EXPECT_NEAR(r.rms_residual_per_s_um[j], sigma_j * std::sqrt(87.0 / 90.0), 0.25 * sigma_j);
  }
}

TEST(MatrixFit, ThreeIndependentPosesDetermineAExactly) {
  const Poses all = individual_moves(kPaperA, 1);
  const std::vector<Vec3> s{all.s[4], all.s[14], all.s[24]};  // 5 um on each actuator
  const std::vector<Vec3> z{all.z[4], all.z[14], all.z[24]};
  const MatrixFitResult r = fit_transmission_matrix(s, z);
  EXPECT_NEAR(r.a.a[1][2], kPaperA(1, 2), 1e-12);
  EXPECT_LT(r.rms_residual_um, 1e-13);
}

TEST(MatrixFit, DetectsRankDeficientDesign) {
  // Only actuators 1 and 2 ever move: Z spans a plane, the third column of A is undetermined.
  Poses p = individual_moves(kPaperA, 1);
  p.s.resize(20);
  p.z.resize(20);
  try {
    fit_transmission_matrix(p.s, p.z);
    FAIL() << "no error";
  } catch (const FitError& e) {
    EXPECT_NE(std::string(e.what()).find("rank-deficient: rank 2 of 3"), std::string::npos)
        << e.what();
  }
  // A point that never moves (z3 = 0 throughout).
  std::vector<Vec3> z{{1, 2, 0}, {3, 1, 0}, {2, 2, 0}, {5, 1, 0}};
  std::vector<Vec3> s{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
  EXPECT_THROW(fit_transmission_matrix(s, z), FitError);
}

TEST(MatrixFit, RejectsTooFewPosesAndNonFiniteValues) {
  const std::vector<Vec3> s{{1, 0, 0}, {0, 1, 0}}, z{{1, 0, 0}, {0, 1, 0}};
  try {
    fit_transmission_matrix(s, z);
    FAIL() << "no error";
  } catch (const FitError& e) {
    EXPECT_NE(std::string(e.what()).find("2 poses; at least 3"), std::string::npos) << e.what();
  }
  const std::vector<Vec3> s3{{1, 0, 0}, {0, 1, 0}, {0, 0, NAN}},
      z3{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  EXPECT_THROW(fit_transmission_matrix(s3, z3), FitError);
  EXPECT_THROW(fit_transmission_matrix(s3, std::span(z3).first(2)), FitError);
}

}  // namespace
}  // namespace piezoshift::calibration
