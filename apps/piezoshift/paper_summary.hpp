#pragma once
// What every `calibrate` of the paper's controller says, as JSON: the library's encoders
// (procedures/calibration_json.hpp), which Python's calibrations use too.
#include "piezoshift/procedures/calibration_json.hpp"

namespace piezoshift::app {

using procedures::matrix_json;
using procedures::paper_calibration_json;

}  // namespace piezoshift::app
