#pragma once
// Least-squares identification of the cubic linearization of the paper's first Eq. 8,
//   Z_S = p3 Z_d^3 + p2 Z_d^2 + p1 Z_d + p0      [um]
// from n recorded points (paper, Section 3, third step): command c_i sent to the controller and
// displacement m_i measured by the interferometer. The controller later sends p(Z_d) to obtain
// the displacement Z_d, so p maps measured to commanded:  c ~ p(m).
//
// Conditioning: the Vandermonde matrix on raw m in [0, 11] um has columns of very different size
// (m^3 up to 1331, 1), so the fit is solved on t = (m - m_mid) / m_half, which lies in [-1, 1]
// (m_mid, m_half: centre and half-width of the measured range), with Eigen's JacobiSVD:
//   c ~ q3 t^3 + q2 t^2 + q1 t + q0,
// and q is expanded back into p (um-based, as the controller uses it). condition_number is that
// of the scaled design [t^3 t^2 t 1]; condition_number_unscaled that of [m^3 m^2 m 1], reported
// to show what the scaling saves.
//
// At least 5 points: 4 unknowns, plus one so that the residual says something about the fit (the
// paper uses 10 or more). Fewer than 4 distinct m, or a design with sigma_min <= kRankRelTol *
// sigma_max, is rank-deficient (FitError).
//
// Residuals r_i = c_i - p(m_i), evaluated with the returned p; rms = sqrt(sum r_i^2 / n).
#include <cstddef>
#include <span>

#include "piezoshift/calibration/fit_error.hpp"
#include "piezoshift/control/cubic_polynomial.hpp"

namespace piezoshift::calibration {

struct PolyFitResult {
  control::CubicPolynomial p;              //!< c = p(m), coefficients in um units
  double rms_residual_um = 0.0;            //!< [um]
  double max_abs_residual_um = 0.0;        //!< [um]
  double condition_number = 0.0;           //!< of the centred and scaled design [-]
  double condition_number_unscaled = 0.0;  //!< of [m^3 m^2 m 1] [-]
  std::size_t points = 0;
};

inline constexpr std::size_t kPolyFitMinPoints = 5;

//! Fits c ~ p(m). Throws FitError for mismatched sizes, fewer than 5 points, a non-finite value
//! (naming the point, 0-based) or a rank-deficient design.
PolyFitResult fit_cubic_polynomial(std::span<const double> measured_um,
                                   std::span<const double> command_um,
                                   double rank_rel_tol = kRankRelTol);

}  // namespace piezoshift::calibration
