#pragma once
// Zernike polynomials in Noll's order and normalisation (Noll 1976, JOSA 66(3):207) on the unit
// disk of the pupil (grid.hpp), and their least-squares fit.
//
//   Z_j(r, t) = sqrt(n + 1) R_n^0(r)                     m = 0
//             = sqrt(2 (n + 1)) R_n^m(r) cos(m t)        m != 0, j even
//             = sqrt(2 (n + 1)) R_n^m(r) sin(m t)        m != 0, j odd
//   R_n^m(r) = sum_{s=0}^{(n-m)/2} (-1)^s (n - s)! / (s! ((n+m)/2 - s)! ((n-m)/2 - s)!) r^(n-2s)
// so that the mean of Z_j^2 over the unit disk is 1: a coefficient is the RMS of its term.
// j = 1 piston, 2 tilt x, 3 tilt y, 4 defocus (power), 5-6 astigmatism, 7-8 coma, 11 spherical.
// The fit solves the normal equations over the mask's finite pixels (not relying on the discrete
// orthogonality that a pixel grid does not have).
#include <span>
#include <vector>

#include "piezoshift/psi/grid.hpp"

namespace piezoshift::psi {

struct NollIndex {
  int n = 0;
  int m = 0;  //!< signed: > 0 the cos term, < 0 the sin term
};

//! (n, m) of Noll index j >= 1; std::invalid_argument for j < 1.
NollIndex noll_index(int j);

class ZernikeBasis {
 public:
  //! Terms j = 1..terms (1 <= terms <= 231, i.e. up to n = 20).
  explicit ZernikeBasis(int terms);
  int terms() const { return static_cast<int>(terms_.size()); }
  //! Z_1..Z_terms at pupil point (x, y) into out (size terms()).
  void evaluate(double x, double y, std::span<double> out) const;

 private:
  struct Term {
    NollIndex nm;
    double norm;
    std::vector<double> radial;  //!< coefficients of (r^2)^p in R_n^m / r^|m|
  };
  std::vector<Term> terms_;
  int max_m_ = 0;
};

//! Least-squares coefficients of Z_1..Z_terms fitted to the finite pixels of surface within the
//! mask (same units as the surface). std::invalid_argument when fewer pixels than terms.
std::vector<double> fit_zernike(const Map& surface, const Mask& mask, int terms);

//! sum_j c_j Z_j over the mask's pupil (NaN outside the mask).
Map zernike_surface(std::span<const double> coefficients, const Mask& mask);

}  // namespace piezoshift::psi
