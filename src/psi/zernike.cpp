#include "piezoshift/psi/zernike.hpp"

#include <cmath>
#include <complex>
#include <cstdlib>
#include <stdexcept>

#include <Eigen/Dense>

namespace piezoshift::psi {
namespace {

double factorial(int k) {
  double f = 1.0;
  for (int i = 2; i <= k; ++i)
    f *= i;
  return f;
}

}  // namespace

NollIndex noll_index(int j) {
  if (j < 1)
    throw std::invalid_argument("Noll index must be >= 1");
  int n = 0;
  while (j > (n + 1) * (n + 2) / 2)
    ++n;
  const int k = j - n * (n + 1) / 2 - 1;  // position within row n
  const int am = (n % 2 == 0) ? 2 * ((k + 1) / 2) : 2 * (k / 2) + 1;
  const int m = (am == 0) ? 0 : (j % 2 == 0 ? am : -am);
  return {n, m};
}

ZernikeBasis::ZernikeBasis(int terms) {
  if (terms < 1 || terms > 231)
    throw std::invalid_argument("Zernike terms must be in 1..231");
  for (int j = 1; j <= terms; ++j) {
    Term t;
    t.nm = noll_index(j);
    const int n = t.nm.n, am = std::abs(t.nm.m);
    t.norm = am == 0 ? std::sqrt(n + 1.0) : std::sqrt(2.0 * (n + 1.0));
    // R_n^m / r^m = sum_s coeff_s r^(n - 2s - m), a polynomial in r^2 of degree (n - m)/2
    const int smax = (n - am) / 2;
    t.radial.assign(static_cast<std::size_t>(smax + 1), 0.0);
    for (int s = 0; s <= smax; ++s) {
      const double c = ((s % 2) ? -1.0 : 1.0) * factorial(n - s) /
                       (factorial(s) * factorial((n + am) / 2 - s) * factorial((n - am) / 2 - s));
      t.radial[static_cast<std::size_t>((n - 2 * s - am) / 2)] = c;
    }
    max_m_ = std::max(max_m_, am);
    terms_.push_back(std::move(t));
  }
}

void ZernikeBasis::evaluate(double x, double y, std::span<double> out) const {
  // (x + i y)^m = r^m exp(i m t) gives r^m cos(m t) and r^m sin(m t) without dividing by r
  std::complex<double> pw[32];
  pw[0] = 1.0;
  for (int m = 1; m <= max_m_; ++m)
    pw[m] = pw[m - 1] * std::complex<double>(x, y);
  const double r2 = x * x + y * y;
  for (std::size_t i = 0; i < terms_.size(); ++i) {
    const Term& t = terms_[i];
    double poly = 0.0;
    for (std::size_t p = t.radial.size(); p-- > 0;)
      poly = poly * r2 + t.radial[p];
    const int am = std::abs(t.nm.m);
    const double ang = t.nm.m >= 0 ? pw[am].real() : pw[am].imag();
    out[i] = t.norm * poly * ang;
  }
}

std::vector<double> fit_zernike(const Map& surface, const Mask& mask, int terms) {
  if (surface.width != mask.width || surface.height != mask.height)
    throw std::invalid_argument("Zernike fit: surface and mask differ in size");
  const ZernikeBasis basis(terms);
  const Pupil pupil = pupil_of(mask);
  constexpr Eigen::Index kChunk = 2048;
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(terms, terms);
  Eigen::VectorXd g = Eigen::VectorXd::Zero(terms);
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> Z(kChunk, terms);
  Eigen::VectorXd s(kChunk);
  Eigen::Index rows = 0;
  std::size_t used = 0;
  auto flush = [&] {
    if (rows == 0)
      return;
    G.selfadjointView<Eigen::Lower>().rankUpdate(Z.topRows(rows).transpose());
    g += Z.topRows(rows).transpose() * s.head(rows);
    rows = 0;
  };
  for (int j = 0; j < mask.height; ++j)
    for (int i = 0; i < mask.width; ++i) {
      const std::size_t p = static_cast<std::size_t>(j) * mask.width + i;
      if (!mask.v[p] || !std::isfinite(surface.v[p]))
        continue;
      basis.evaluate(pupil.x(i), pupil.y(j),
                     std::span<double>(Z.row(rows).data(), static_cast<std::size_t>(terms)));
      s(rows) = surface.v[p];
      ++used;
      if (++rows == kChunk)
        flush();
    }
  flush();
  if (used < static_cast<std::size_t>(terms))
    throw std::invalid_argument("Zernike fit: fewer valid pixels than terms");
  G.triangularView<Eigen::Upper>() = G.transpose();
  const Eigen::VectorXd c = G.ldlt().solve(g);
  return {c.data(), c.data() + c.size()};
}

Map zernike_surface(std::span<const double> coefficients, const Mask& mask) {
  const int terms = static_cast<int>(coefficients.size());
  Map out(mask.width, mask.height, std::nan(""));
  if (terms == 0)
    return out;
  const ZernikeBasis basis(terms);
  const Pupil pupil = pupil_of(mask);
  std::vector<double> z(static_cast<std::size_t>(terms));
  for (int j = 0; j < mask.height; ++j)
    for (int i = 0; i < mask.width; ++i) {
      const std::size_t p = static_cast<std::size_t>(j) * mask.width + i;
      if (!mask.v[p])
        continue;
      basis.evaluate(pupil.x(i), pupil.y(j), z);
      double v = 0.0;
      for (int k = 0; k < terms; ++k)
        v += coefficients[static_cast<std::size_t>(k)] * z[static_cast<std::size_t>(k)];
      out.v[p] = v;
    }
  return out;
}

}  // namespace piezoshift::psi
