#pragma once
// Calibration stage 3 (paper, Section 3, third step): the cubic polynomial, with the PID loops
// and the identified A working and the polynomial set to the identity. For n equally spaced
// commands c_k over [0, max_um] (the paper: 10 or more):
//   drive the three points to Z_d = c_k; settle; read the interferometer (static, 1 s)
//   m_k = mean of the three points' readings (the phase shifter's displacement)
// and p fits c ~ p(m) (poly_fit.hpp), so that the controller, sending Z_S = p(Z_d), obtains
// Z_r ~ Z_d. A command at which any PID sits at its output limit is not a tracked point; it is
// left out of the fit and counted.
#include <cstddef>
#include <vector>

#include "piezoshift/calibration/poly_fit.hpp"
#include "piezoshift/rig/bench.hpp"
#include "piezoshift/rig/progress.hpp"

namespace piezoshift::calibration {

struct PolynomialIdentificationOptions {
  std::size_t points = 12;  //!< equally spaced commands, 0 and max_um included
  double max_um = 11.0;     //!< the paper's linearity span (Section 4.2)
  double settle_s = 1.0;
};

struct PolynomialIdentificationResult {
  PolyFitResult fit;
  std::vector<double> command_um;    //!< c_k of the points used
  std::vector<double> measured_um;   //!< m_k
  std::size_t saturated_points = 0;  //!< left out: a PID at its limit
  double simulated_time_s = 0.0;
};

//! Runs the procedure on the bench, whose controller must already carry the identified gains and
//! A (its polynomial is replaced by the identity for the run and left so). Throws FitError when
//! the data cannot give p.
PolynomialIdentificationResult identify_polynomial(
    rig::Bench& bench, const PolynomialIdentificationOptions& options = {},
    const rig::Progress& progress = {});

}  // namespace piezoshift::calibration
