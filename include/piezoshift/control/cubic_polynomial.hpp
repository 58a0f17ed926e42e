#pragma once
// Cubic polynomial linearization, the first Eq. 8 of the paper:
//   Z_S = p3 Z_d^3 + p2 Z_d^2 + p1 Z_d + p0            (all in um)
// with its derivative and a monotonic inverse (solve p(x) = y for x on an interval where p is
// strictly monotonic), used to check calibrations and by the twin's analysis tools.
//
// Real-time safe: no heap, no exceptions, no I/O.
#include <cstdint>

namespace piezoshift::control {

struct CubicPolynomial {
  // Paper, Section 4: p3 = -0.0001009, p2 = 0.000389, p1 = 1.014, p0 = 0.2914 (um-based).
  double p3 = -0.0001009;  //!< [1/um^2]
  double p2 = 0.000389;    //!< [1/um]
  double p1 = 1.014;       //!< [-]
  double p0 = 0.2914;      //!< [um]

  static constexpr CubicPolynomial identity() noexcept { return {0.0, 0.0, 1.0, 0.0}; }

  //! p(x), Horner form.
  constexpr double operator()(double x) const noexcept { return ((p3 * x + p2) * x + p1) * x + p0; }
  //! dp/dx
  constexpr double derivative(double x) const noexcept {
    return (3.0 * p3 * x + 2.0 * p2) * x + p1;
  }
};

enum class InverseStatus : std::uint8_t {
  kOk,
  kOutOfRange,    //!< y is not between p(lo) and p(hi)
  kNotMonotonic,  //!< p' changes sign on [lo, hi]
  kBadInterval,   //!< lo >= hi or a non-finite bound
};

struct InverseResult {
  double x = 0.0;
  InverseStatus status = InverseStatus::kOk;
};

//! x in [lo, hi] with p(x) = y, to |p(x) - y| <= tol. Safeguarded Newton (bisection fallback),
//! so it always converges when p is monotonic on the interval.
constexpr InverseResult inverse(const CubicPolynomial& p, double y, double lo, double hi,
                                double tol = 1e-12) noexcept {
  if (!(lo < hi) || lo - lo != 0.0 || hi - hi != 0.0)
    return {0.0, InverseStatus::kBadInterval};
  // p' is quadratic: monotonic on [lo, hi] iff p' keeps one sign at both ends and at its vertex.
  const double d_lo = p.derivative(lo);
  const double d_hi = p.derivative(hi);
  bool monotonic = (d_lo > 0.0 && d_hi > 0.0) || (d_lo < 0.0 && d_hi < 0.0);
  if (monotonic && p.p3 != 0.0) {
    const double vertex = -p.p2 / (3.0 * p.p3);
    if (vertex > lo && vertex < hi) {
      const double d_v = p.derivative(vertex);
      monotonic = (d_lo > 0.0) ? d_v > 0.0 : d_v < 0.0;
    }
  }
  if (!monotonic)
    return {0.0, InverseStatus::kNotMonotonic};
  const bool increasing = d_lo > 0.0;
  double a = lo;
  double b = hi;
  const double ya = p(a) - y;
  const double yb = p(b) - y;
  if (ya == 0.0)
    return {a, InverseStatus::kOk};
  if (yb == 0.0)
    return {b, InverseStatus::kOk};
  if ((ya > 0.0) == (yb > 0.0))
    return {0.0, InverseStatus::kOutOfRange};
  double x = a + (b - a) * (-ya) / (yb - ya);  // secant start
  for (int i = 0; i < 100; ++i) {
    const double f = p(x) - y;
    if ((f < 0.0 ? -f : f) <= tol)
      break;
    // keep the bracket [a, b] around the root
    if ((f > 0.0) == increasing) {
      b = x;
    } else {
      a = x;
    }
    const double d = p.derivative(x);
    double next = x - f / d;
    if (!(next > a && next < b))
      next = 0.5 * (a + b);
    if (next == x)
      break;
    x = next;
  }
  return {x, InverseStatus::kOk};
}

}  // namespace piezoshift::control
