#pragma once
// Cubic polynomial linearization, the first Eq. 8 of the paper:
//   Z_S = p3 Z_d^3 + p2 Z_d^2 + p1 Z_d + p0            (all in um)
// with its derivative and a monotonic inverse (solve p(x) = y for x on an interval where p is
// strictly monotonic), used to check calibrations and by the twin's analysis tools.
//
// Real-time safe: no heap, no exceptions, no I/O.
#include <cstdint>
#include <type_traits>

namespace piezoshift::control {

template <class T>
struct BasicCubicPolynomial {
  // Paper, Section 4: p3 = -0.0001009, p2 = 0.000389, p1 = 1.014, p0 = 0.2914 (um-based).
  T p3 = T(-0.0001009);  //!< [1/um^2]
  T p2 = T(0.000389);    //!< [1/um]
  T p1 = T(1.014);       //!< [-]
  T p0 = T(0.2914);      //!< [um]

  static constexpr BasicCubicPolynomial identity() noexcept { return {T(0), T(0), T(1), T(0)}; }

  //! p(x), Horner form.
  constexpr T operator()(T x) const noexcept { return ((p3 * x + p2) * x + p1) * x + p0; }
  //! dp/dx
  constexpr T derivative(T x) const noexcept { return (T(3) * p3 * x + T(2) * p2) * x + p1; }
};

using CubicPolynomial = BasicCubicPolynomial<double>;

template <class To, class From>
constexpr BasicCubicPolynomial<To> convert(const BasicCubicPolynomial<From>& p) noexcept {
  return {static_cast<To>(p.p3), static_cast<To>(p.p2), static_cast<To>(p.p1),
          static_cast<To>(p.p0)};
}

enum class InverseStatus : std::uint8_t {
  kOk,
  kOutOfRange,    //!< y is not between p(lo) and p(hi)
  kNotMonotonic,  //!< p' changes sign on [lo, hi]
  kBadInterval,   //!< lo >= hi or a non-finite bound
};

template <class T>
struct BasicInverseResult {
  T x = T(0);
  InverseStatus status = InverseStatus::kOk;
};

using InverseResult = BasicInverseResult<double>;

//! x in [lo, hi] with p(x) = y, to |p(x) - y| <= tol. Safeguarded Newton (bisection fallback),
//! so it always converges when p is monotonic on the interval.
template <class T>
constexpr BasicInverseResult<T> inverse(const BasicCubicPolynomial<T>& p, std::type_identity_t<T> y,
                                        std::type_identity_t<T> lo, std::type_identity_t<T> hi,
                                        std::type_identity_t<T> tol = T(1e-12)) noexcept {
  if (!(lo < hi) || lo - lo != T(0) || hi - hi != T(0))
    return {T(0), InverseStatus::kBadInterval};
  // p' is quadratic: monotonic on [lo, hi] iff p' keeps one sign at both ends and at its vertex.
  const T d_lo = p.derivative(lo);
  const T d_hi = p.derivative(hi);
  bool monotonic = (d_lo > T(0) && d_hi > T(0)) || (d_lo < T(0) && d_hi < T(0));
  if (monotonic && p.p3 != T(0)) {
    const T vertex = -p.p2 / (T(3) * p.p3);
    if (vertex > lo && vertex < hi) {
      const T d_v = p.derivative(vertex);
      monotonic = (d_lo > T(0)) ? d_v > T(0) : d_v < T(0);
    }
  }
  if (!monotonic)
    return {T(0), InverseStatus::kNotMonotonic};
  const bool increasing = d_lo > T(0);
  T a = lo;
  T b = hi;
  const T ya = p(a) - y;
  const T yb = p(b) - y;
  if (ya == T(0))
    return {a, InverseStatus::kOk};
  if (yb == T(0))
    return {b, InverseStatus::kOk};
  if ((ya > T(0)) == (yb > T(0)))
    return {T(0), InverseStatus::kOutOfRange};
  T x = a + (b - a) * (-ya) / (yb - ya);  // secant start
  for (int i = 0; i < 100; ++i) {
    const T f = p(x) - y;
    if ((f < T(0) ? -f : f) <= tol)
      break;
    // keep the bracket [a, b] around the root
    if ((f > T(0)) == increasing) {
      b = x;
    } else {
      a = x;
    }
    const T d = p.derivative(x);
    T next = x - f / d;
    if (!(next > a && next < b))
      next = T(0.5) * (a + b);
    if (next == x)
      break;
    x = next;
  }
  return {x, InverseStatus::kOk};
}

}  // namespace piezoshift::control
