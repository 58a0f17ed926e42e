#include "piezoshift/plant/mechanics.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace piezoshift::plant {
namespace {

bool symmetric_positive_definite(const Eigen::Matrix3d& m) {
  if (!m.allFinite() || !m.isApprox(m.transpose(), 1e-12))
    return false;
  return Eigen::LLT<Eigen::Matrix3d>(m).info() == Eigen::Success && m.diagonal().minCoeff() > 0.0;
}

}  // namespace

LinearMechanics::LinearMechanics(const Eigen::Matrix3d& mass_kg,
                                 const Eigen::Matrix3d& stiffness_N_per_m, double damping_ratio,
                                 double step_s) {
  if (!symmetric_positive_definite(mass_kg))
    throw std::invalid_argument("mechanics: the mass matrix is not symmetric positive definite");
  if (!symmetric_positive_definite(stiffness_N_per_m))
    throw std::invalid_argument(
        "mechanics: the stiffness matrix is not symmetric positive definite");
  if (!(damping_ratio >= 0.0 && damping_ratio < 1.0))
    throw std::invalid_argument("mechanics: the damping ratio must be in [0, 1)");
  if (!(step_s > 0.0) || !std::isfinite(step_s))
    throw std::invalid_argument("mechanics: the step must be positive");

  // K phi = lambda M phi; Eigen returns eigenvalues ascending and M-normalized eigenvectors.
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix3d> es(stiffness_N_per_m, mass_kg);
  if (es.info() != Eigen::Success)
    throw std::invalid_argument("mechanics: the eigenproblem did not converge");
  const Eigen::Matrix3d phi = es.eigenvectors();
  for (std::size_t r = 0; r < 3; ++r) {
    const auto ri = static_cast<Eigen::Index>(r);
    for (std::size_t i = 0; i < 3; ++i) {
      const auto ii = static_cast<Eigen::Index>(i);
      in_[r][i] = 1e6 * phi(ii, ri);
      out_[i][r] = phi(ii, ri);
    }
    const double w = std::sqrt(es.eigenvalues()(ri));
    f_[r] = w / (2.0 * std::numbers::pi);
    const double z = damping_ratio;
    const double s = z * w;
    const double wd = w * std::sqrt(1.0 - z * z);
    const double e = std::exp(-s * step_s);
    const double c = std::cos(wd * step_s), sn = std::sin(wd * step_s);
    const double a11 = e * (c + s / wd * sn), a12 = e * sn / wd;
    const double a21 = -e * w * w / wd * sn, a22 = e * (c - s / wd * sn);
    mode_[r].by_q = {a11, a21};
    mode_[r].by_v = {a12, a22};
    mode_[r].by_u = {(1.0 - a11) / (w * w), a12};
  }
}

Eigen::Matrix3d LinearMechanics::mode_shapes() const {
  Eigen::Matrix3d phi;
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t r = 0; r < 3; ++r)
      phi(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(r)) = out_[i][r];
  return phi;
}

}  // namespace piezoshift::plant
