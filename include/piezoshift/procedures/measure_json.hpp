#pragma once
// The one encoder of a measurement's outcome (measure_outcome.hpp): what `measure --json` prints
// and writes as measurement.json, and what Python's measure() returns, converted to a dict.
#include <string>

#include <nlohmann/json.hpp>

#include "piezoshift/instrument/sequence.hpp"
#include "piezoshift/procedures/measure_outcome.hpp"

namespace piezoshift::procedures {

//! Where the CLI wrote the measurement: measurement.json's "out", and "out_given" when --out had
//! become something else while it ran (both left out when "").
struct MeasureWritten {
  std::string out;
  std::string out_given;
};

//! {"valid": false, "reason": ...} for a sequence that is not valid; else the summary: what ran,
//! the steps, the analysis, the figures against the truth, timing, exposures, lock and hold.
nlohmann::json measure_json(const MeasureOutcome& o, const MeasureWritten& written = {});

//! Each exposure's record, measure_json's "exposures".
nlohmann::json exposures_json(const instrument::SequenceResult& s);

//! The hold's summary, measure_json's "hold": duration, frames, their mean interval, the path's
//! RMS and largest excursion from its set point (twin truth, else null), the lock's states.
nlohmann::json hold_json(const instrument::SequenceResult& s);

}  // namespace piezoshift::procedures
