#pragma once
// What `calibrate --controller improved` and `fit improved` say about the improved controller
// they identified: its channel models, the plate's mode, the shaper and the correction; as JSON
// (keys documented in docs/calibration.md) and as text. And the two files the identification
// fits, in the formats `fit improved` reads (docs/files.md).
#include <array>
#include <string>

#include <nlohmann/json.hpp>

#include "piezoshift/calibration/hysteresis_identification.hpp"
#include "piezoshift/calibration/improved_calibration.hpp"
#include "piezoshift/calibration/mode_identification.hpp"

namespace piezoshift::app {

struct ImprovedSummary {
  const control::ImprovedParams& controller;
  const std::array<calibration::HysteresisFit, 3>& model;
  const calibration::PlateModeEstimate& mode;
  bool shaped;
};

nlohmann::json improved_json(const ImprovedSummary& s);
void print_improved(const ImprovedSummary& s);

//! The excitation (t_s, u1_um..u3_um, sgs1_um..sgs3_um) and the ring-down (t_s, measured_um)
//! of a calibration outcome, written to these paths.
void write_improved_records(const calibration::ImprovedCalibrationOutcome& ic,
                            const std::string& excitation_file, const std::string& mode_file);

}  // namespace piezoshift::app
