#pragma once
// Least squares of y on a subset of fixed columns B and optionally one more column z, over the
// same rows again and again (the channel-model fit's creep passes and operator drops,
// hysteresis_identification.hpp). B = Q R once (Eigen's Householder QR); then
//   ||y - B_S w - g z||^2 = ||Q'y - R_S w - g Q'z||^2 + ||y_p - g z_p||^2
// (y_p, z_p: the parts outside Q's span), a problem of (columns + 1) rows. Exact in exact
// arithmetic; each solve costs Q'z (rows x columns) instead of a QR of the whole record
// (370 000 rows at 10 kHz).
#include <Eigen/Dense>
#include <cstddef>
#include <limits>
#include <vector>

namespace piezoshift::calibration {

struct LeastSquaresSolution {
  Eigen::VectorXd x;  //!< the coefficients of the chosen columns, z's last
  //! sqrt(||residual||^2 / rows) over the whole record
  double rms = std::numeric_limits<double>::infinity();
};

class CompressedLeastSquares {
 public:
  //! B: rows >= columns, full column rank (the caller's regressors); y: one value per row.
  CompressedLeastSquares(const Eigen::MatrixXd& B, const Eigen::VectorXd& y);

  //! The fit on the columns `cols` of B (indices, any order) and on z when z is not empty.
  [[nodiscard]] LeastSquaresSolution solve(const std::vector<std::size_t>& cols,
                                           const Eigen::VectorXd& z) const;

 private:
  Eigen::Index rows_;
  Eigen::MatrixXd q_, r_;
  Eigen::VectorXd qy_, y_perp_;
};

}  // namespace piezoshift::calibration
