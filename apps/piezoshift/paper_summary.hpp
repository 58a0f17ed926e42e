#pragma once
// What every `calibrate` of the paper's controller says, as JSON, whichever interferometer read
// it (the twin's XL-80, a guided session's, the Fizeau's fringes): the gains, A and p found and
// the fits' residuals (keys documented in docs/calibration.md).
#include <nlohmann/json.hpp>

#include "piezoshift/calibration/matrix_identification.hpp"
#include "piezoshift/calibration/polynomial_identification.hpp"
#include "piezoshift/control/semi_closed_loop.hpp"

namespace piezoshift::app {

//! A's rows as a JSON array of arrays.
nlohmann::json matrix_json(const control::Mat3& a);

//! pid_gains, A, p, A_rms_residual_um, condition_number, p_rms_residual_um.
nlohmann::json paper_calibration_json(
    const control::SemiClosedLoopParams& controller,
    const calibration::MatrixIdentificationResult& matrix,
    const calibration::PolynomialIdentificationResult& polynomial);

}  // namespace piezoshift::app
