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
#include "piezoshift/io/csv_table.hpp"

namespace piezoshift::app {

struct ImprovedSummary {
  const control::ImprovedParams& controller;
  const std::array<calibration::HysteresisFit, 3>& model;
  const calibration::PlateModeEstimate& mode;
  bool shaped;
  //! Stage 7 on the twin; nullptr from records (`fit improved`: no plant to try moves on)
  const calibration::LargeMoveTrial* large_move = nullptr;
  //! Stage 5b's verdict on the loop's rate on the twin; nullptr without a laser interferometer
  //! or from records
  const calibration::RateVerdict* rate_verdict = nullptr;
};

nlohmann::json improved_json(const ImprovedSummary& s);
void print_improved(const ImprovedSummary& s);

//! The excitation (t_s, u1_um..u3_um, sgs1_um..sgs3_um) and the ring-down (t_s, measured_um)
//! of a calibration outcome, each file replaced atomically and promising its rows ("# rows = N"
//! before the data) so that `fit improved` can tell a copy cut short.
void write_improved_records(const calibration::ImprovedCalibrationOutcome& ic,
                            const std::string& excitation_file, const std::string& mode_file);

//! A record as `fit improved` reads it: a last line without its newline, or fewer (or more) data
//! rows than a "# rows = N" comment promises, is a file cut short: InputError naming it.
io::CsvTable load_record(const std::string& path);

}  // namespace piezoshift::app
