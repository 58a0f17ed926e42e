#include "piezoshift/calibration/poly_fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/core.h>
#include <Eigen/Dense>

namespace piezoshift::calibration {
namespace {

Eigen::MatrixXd vandermonde(const Eigen::VectorXd& x) {
  Eigen::MatrixXd v(x.size(), 4);
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    v(i, 0) = x(i) * x(i) * x(i);
    v(i, 1) = x(i) * x(i);
    v(i, 2) = x(i);
    v(i, 3) = 1.0;
  }
  return v;
}

double condition(const Eigen::VectorXd& sigma) {
  const double lo = sigma.minCoeff();
  return lo > 0.0 ? sigma.maxCoeff() / lo : std::numeric_limits<double>::infinity();
}

}  // namespace

PolyFitResult fit_cubic_polynomial(std::span<const double> measured_um,
                                   std::span<const double> command_um, double rank_rel_tol) {
  if (measured_um.size() != command_um.size()) {
    throw FitError(fmt::format("polynomial fit: {} measured values but {} commands",
                               measured_um.size(), command_um.size()));
  }
  const std::size_t n = measured_um.size();
  if (n < kPolyFitMinPoints) {
    throw FitError(fmt::format(
        "polynomial fit: {} point{}; at least {} are needed (4 coefficients, plus one for a "
        "residual)",
        n, n == 1 ? "" : "s", kPolyFitMinPoints));
  }
  const auto ni = static_cast<Eigen::Index>(n);
  Eigen::VectorXd m(ni), c(ni);
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(measured_um[i]) || !std::isfinite(command_um[i]))
      throw FitError(fmt::format("polynomial fit: point {} has a non-finite value", i));
    m(static_cast<Eigen::Index>(i)) = measured_um[i];
    c(static_cast<Eigen::Index>(i)) = command_um[i];
  }
  const double m_lo = m.minCoeff();
  const double m_hi = m.maxCoeff();
  const double mid = 0.5 * (m_lo + m_hi);
  const double half = 0.5 * (m_hi - m_lo);
  std::vector<double> distinct(measured_um.begin(), measured_um.end());
  std::sort(distinct.begin(), distinct.end());
  const auto n_distinct =
      static_cast<std::size_t>(std::unique(distinct.begin(), distinct.end()) - distinct.begin());

  Eigen::VectorXd sigma = Eigen::VectorXd::Zero(4);
  Eigen::MatrixXd v;
  if (half > 0.0) {
    v = vandermonde(((m.array() - mid) / half).matrix());
    sigma = Eigen::JacobiSVD<Eigen::MatrixXd>(v).singularValues();
  }
  if (n_distinct < 4 || !(sigma(3) > rank_rel_tol * sigma(0))) {
    throw FitError(fmt::format(
        "polynomial fit: the design is rank-deficient: {} distinct measured_um value{} (a cubic "
        "needs at least 4 distinct displacements spread over the travel)",
        n_distinct, n_distinct == 1 ? "" : "s"));
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(v, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::Vector4d q = svd.solve(c);  // [q3 q2 q1 q0] in t

  // Expand q(t), t = a m + b with a = 1/half, b = -mid/half, into powers of m.
  const double a = 1.0 / half;
  const double b = -mid / half;
  PolyFitResult out;
  out.points = n;
  out.p.p3 = q(0) * a * a * a;
  out.p.p2 = q(0) * 3.0 * a * a * b + q(1) * a * a;
  out.p.p1 = q(0) * 3.0 * a * b * b + q(1) * 2.0 * a * b + q(2) * a;
  out.p.p0 = q(0) * b * b * b + q(1) * b * b + q(2) * b + q(3);

  double sum_sq = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double r = command_um[i] - out.p(measured_um[i]);
    sum_sq += r * r;
    out.max_abs_residual_um = std::max(out.max_abs_residual_um, std::abs(r));
  }
  out.rms_residual_um = std::sqrt(sum_sq / static_cast<double>(n));
  out.condition_number = condition(svd.singularValues());
  out.condition_number_unscaled =
      condition(Eigen::JacobiSVD<Eigen::MatrixXd>(vandermonde(m)).singularValues());
  return out;
}

}  // namespace piezoshift::calibration
