#include "piezoshift/calibration/matrix_fit.hpp"

#include <cmath>
#include <limits>

#include <fmt/core.h>
#include <Eigen/Dense>

namespace piezoshift::calibration {
namespace {

double condition(const Eigen::VectorXd& sigma) {
  const double lo = sigma.minCoeff();
  return lo > 0.0 ? sigma.maxCoeff() / lo : std::numeric_limits<double>::infinity();
}

}  // namespace

MatrixFitResult fit_transmission_matrix(std::span<const control::Vec3> s_um,
                                        std::span<const control::Vec3> z_um, double rank_rel_tol) {
  if (s_um.size() != z_um.size()) {
    throw FitError(fmt::format("matrix fit: {} S rows but {} Z rows", s_um.size(), z_um.size()));
  }
  const std::size_t n = s_um.size();
  if (n < kMatrixFitMinPoses) {
    throw FitError(fmt::format(
        "matrix fit: {} pose{}; at least {} are needed (each row of A has 3 unknowns, one "
        "equation per pose), and more than 3 to judge the fit by its residual",
        n, n == 1 ? "" : "s", kMatrixFitMinPoses));
  }
  Eigen::MatrixXd z(n, 3), s(n, 3);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < 3; ++j) {
      if (!std::isfinite(s_um[i][j]) || !std::isfinite(z_um[i][j]))
        throw FitError(fmt::format("matrix fit: pose {} has a non-finite value", i));
      z(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = z_um[i][j];
      s(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = s_um[i][j];
    }
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(z, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd sigma = svd.singularValues();  // descending
  if (!(sigma(2) > rank_rel_tol * sigma(0))) {
    int rank = 0;
    for (Eigen::Index k = 0; k < 3; ++k)
      rank += sigma(k) > rank_rel_tol * sigma(0) && sigma(k) > 0.0 ? 1 : 0;
    throw FitError(fmt::format(
        "matrix fit: the Z design (z1_um, z2_um, z3_um over {} poses) is rank-deficient: rank {} "
        "of 3, sigma_min / sigma_max = {:.3g} <= {:.0e}; the three points must move "
        "independently (e.g. move each actuator on its own)",
        n, rank, sigma(0) > 0.0 ? sigma(2) / sigma(0) : 0.0, rank_rel_tol));
  }
  const Eigen::Matrix3d at = svd.solve(s);  // A^T
  const Eigen::MatrixXd r = s - z * at;

  MatrixFitResult out;
  out.poses = n;
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col)
      out.a.a[row][col] = at(col, row);
  }
  for (Eigen::Index j = 0; j < 3; ++j)
    out.rms_residual_per_s_um[j] = std::sqrt(r.col(j).squaredNorm() / static_cast<double>(n));
  out.rms_residual_um = std::sqrt(r.squaredNorm() / static_cast<double>(3 * n));
  out.design_condition_number = condition(sigma);
  out.condition_number = condition(Eigen::JacobiSVD<Eigen::Matrix3d>(at).singularValues());
  return out;
}

}  // namespace piezoshift::calibration
