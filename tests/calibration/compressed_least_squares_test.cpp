// CompressedLeastSquares against the plain answer: a column-pivoting QR of the chosen columns over
// every row (an independent route through Eigen), on random problems with noise.
#include "piezoshift/calibration/compressed_least_squares.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "gaussian_noise.hpp"

namespace piezoshift::calibration {
namespace {

struct Problem {
  Eigen::MatrixXd B;
  Eigen::VectorXd y, z;
};

Problem random_problem(std::uint64_t seed) {
  test::GaussianNoise n(seed, 1.0);
  Problem p;
  p.B.resize(400, 6);
  p.y.resize(400);
  p.z.resize(400);
  for (Eigen::Index k = 0; k < 400; ++k) {
    for (Eigen::Index j = 0; j < 6; ++j)
      p.B(k, j) = n();
    p.z(k) = n();
  }
  // y from columns 0, 2, 5 and z, plus noise: the residual is not zero.
  p.y = 0.7 * p.B.col(0) - 1.3 * p.B.col(2) + 0.2 * p.B.col(5) + 0.05 * p.z;
  for (Eigen::Index k = 0; k < 400; ++k)
    p.y(k) += 0.1 * n();
  return p;
}

// The plain fit: the chosen columns (and z) assembled over all rows, solved, its rms residual.
LeastSquaresSolution plain(const Problem& p, const std::vector<std::size_t>& cols,
                           const Eigen::VectorXd& z) {
  const auto k = static_cast<Eigen::Index>(cols.size());
  Eigen::MatrixXd A(p.B.rows(), k + (z.size() > 0 ? 1 : 0));
  for (Eigen::Index j = 0; j < k; ++j)
    A.col(j) = p.B.col(static_cast<Eigen::Index>(cols[static_cast<std::size_t>(j)]));
  if (z.size() > 0)
    A.col(k) = z;
  LeastSquaresSolution s;
  s.x = A.colPivHouseholderQr().solve(p.y);
  s.rms = std::sqrt((A * s.x - p.y).squaredNorm() / static_cast<double>(p.B.rows()));
  return s;
}

void expect_same(const LeastSquaresSolution& got, const LeastSquaresSolution& want) {
  ASSERT_EQ(got.x.size(), want.x.size());
  for (Eigen::Index j = 0; j < got.x.size(); ++j)
    EXPECT_NEAR(got.x(j), want.x(j), 1e-12) << "coefficient " << j;
  EXPECT_NEAR(got.rms, want.rms, 1e-13);
  EXPECT_GT(want.rms, 0.05);  // noise 0.1 rms: a real residual, not a consistent system
}

TEST(CompressedLeastSquares, EqualsThePlainFitOnEverySubsetWithAndWithoutTheExtraColumn) {
  for (const std::uint64_t seed : {1u, 2u, 3u}) {
    const Problem p = random_problem(seed);
    const CompressedLeastSquares ls(p.B, p.y);
    for (const std::vector<std::size_t>& cols :
         {std::vector<std::size_t>{0, 1, 2, 3, 4, 5}, std::vector<std::size_t>{5, 0, 2},
          std::vector<std::size_t>{1, 3}}) {
      expect_same(ls.solve(cols, p.z), plain(p, cols, p.z));
      expect_same(ls.solve(cols, Eigen::VectorXd{}), plain(p, cols, Eigen::VectorXd{}));
    }
  }
}

TEST(CompressedLeastSquares, RecoversTheCoefficientsOfANoiselessRecord) {
  Problem p = random_problem(4);
  p.y = 0.7 * p.B.col(0) - 1.3 * p.B.col(2) + 0.2 * p.B.col(5) + 0.05 * p.z;
  const LeastSquaresSolution s = CompressedLeastSquares(p.B, p.y).solve({0, 2, 5}, p.z);
  ASSERT_EQ(s.x.size(), 4);
  EXPECT_NEAR(s.x(0), 0.7, 1e-12);
  EXPECT_NEAR(s.x(1), -1.3, 1e-12);
  EXPECT_NEAR(s.x(2), 0.2, 1e-12);
  EXPECT_NEAR(s.x(3), 0.05, 1e-12);
  EXPECT_LT(s.rms, 1e-12);
}

TEST(CompressedLeastSquares, AnExtraColumnInsideTheFixedOnesSpanAddsNoRow) {
  // z in the span of B but not of the chosen columns: alpha = 0 (to rounding), and the fit is
  // still the plain one.
  Problem p = random_problem(5);
  p.z = 2.0 * p.B.col(1) - p.B.col(4);
  const std::vector<std::size_t> cols{0, 2, 5};
  expect_same(CompressedLeastSquares(p.B, p.y).solve(cols, p.z), plain(p, cols, p.z));
}

}  // namespace
}  // namespace piezoshift::calibration
