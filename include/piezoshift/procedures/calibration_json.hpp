#pragma once
// The encoders of a calibration's outcome: what every `calibrate` of the paper's controller says,
// whichever interferometer read it (the twin's XL-80, a guided session's, the Fizeau's fringes),
// and the calibration from fringes' own figures, which `calibrate --interferometer fizeau --json`
// prints and Python's calibrate_from_fringes() returns (keys documented in docs/calibration.md and
// docs/fizeau.md).
#include <nlohmann/json.hpp>

#include "piezoshift/calibration/matrix_identification.hpp"
#include "piezoshift/calibration/polynomial_identification.hpp"
#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/instrument/fringe_calibration.hpp"

namespace piezoshift::procedures {

//! A's rows as a JSON array of arrays.
nlohmann::json matrix_json(const control::Mat3& a);

//! pid_gains, A, p, A_rms_residual_um, condition_number, p_rms_residual_um.
nlohmann::json paper_calibration_json(
    const control::SemiClosedLoopParams& controller,
    const calibration::MatrixIdentificationResult& matrix,
    const calibration::PolynomialIdentificationResult& polynomial);

//! paper_calibration_json's, and pupil_source, p_points, p_skipped_commands, frames,
//! stage2_simulated_s, stage3_simulated_s and wall_s.
nlohmann::json fringe_calibration_json(const instrument::FringeCalibrationOutcome& r);

}  // namespace piezoshift::procedures
