#include "piezoshift/calibration/compressed_least_squares.hpp"

#include <algorithm>
#include <cmath>

namespace piezoshift::calibration {

CompressedLeastSquares::CompressedLeastSquares(const Eigen::MatrixXd& B, const Eigen::VectorXd& y)
    : rows_(B.rows()) {
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(B);
  q_ = qr.householderQ() * Eigen::MatrixXd::Identity(B.rows(), B.cols());
  r_ = qr.matrixQR().topRows(B.cols()).triangularView<Eigen::Upper>();
  qy_ = q_.transpose() * y;
  y_perp_ = y - q_ * qy_;
}

LeastSquaresSolution CompressedLeastSquares::solve(const std::vector<std::size_t>& cols,
                                                   const Eigen::VectorXd& z) const {
  const auto k = static_cast<Eigen::Index>(cols.size());
  const Eigen::Index m = r_.rows();
  const bool with_z = z.size() > 0;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(m + 1, k + (with_z ? 1 : 0));
  Eigen::VectorXd b = Eigen::VectorXd::Zero(m + 1);
  for (Eigen::Index j = 0; j < k; ++j)
    A.col(j).head(m) = r_.col(static_cast<Eigen::Index>(cols[static_cast<std::size_t>(j)]));
  b.head(m) = qy_;
  double rest = y_perp_.squaredNorm();
  if (with_z) {
    // z = Q (Q'z) + alpha e, e a unit vector outside Q's span: one more row.
    const Eigen::VectorXd qz = q_.transpose() * z;
    const Eigen::VectorXd z_perp = z - q_ * qz;
    const double alpha = z_perp.norm();
    A.col(k).head(m) = qz;
    A(m, k) = alpha;
    if (alpha > 0.0) {
      const double along = z_perp.dot(y_perp_) / alpha;
      b(m) = along;
      rest -= along * along;
    }
  }
  LeastSquaresSolution s;
  s.x = A.colPivHouseholderQr().solve(b);
  const double sq = (A * s.x - b).squaredNorm() + std::max(rest, 0.0);
  s.rms = std::sqrt(sq / static_cast<double>(rows_));
  return s;
}

}  // namespace piezoshift::calibration
