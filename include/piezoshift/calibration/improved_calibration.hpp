#pragma once
// Calibration of the improved controller (issue 12): the paper's static map (stages 2 and 3: A
// and p, the gauge-to-plate path) and the identification of the improved controller's own
// models, on the twin through the shipping loop. Work in progress: for now it returns the paper's
// calibration.
#include <cstdint>

#include "piezoshift/calibration/calibration_procedure.hpp"

namespace piezoshift::calibration {

struct ImprovedCalibrationOptions {
  CalibrationOptions paper{};  //!< the static map's stages (A, p), as the paper's procedure
};

struct ImprovedCalibrationOutcome {
  control::SemiClosedLoopParams controller;  //!< the improved controller to load
  CalibrationOutcome static_map;             //!< stages 1 to 3 as the paper's procedure ran them
};

//! base supplies the sample time, limits and scaling.
ImprovedCalibrationOutcome calibrate_improved(const io::ProjectConfig& config,
                                              const control::SemiClosedLoopParams& base,
                                              std::uint64_t seed,
                                              const ImprovedCalibrationOptions& options = {},
                                              const experiments::Progress& progress = {});

}  // namespace piezoshift::calibration
