#pragma once
// What the calibrations cost on the simulated bench (rig/procedure_cost.hpp), measured with the
// simulation meter on the built-in configuration (static_average_s = 1 and 2 s):
//
//   calibrate_with_travel, one PID candidate (the start-up calibration of `run`, `serve` and
//   `measure` on the twin without --calibration):   82.5 s + 76 s per second of static window
//   each further PID candidate scored:               rest 0.2 s + step_duration_s + one tick
//   (the default grid, 240 candidates, makes `calibrate`'s 325.8 s)
//   calibrate_improved, then the travel (`calibrate --controller improved`):
//                                                    277.8 s + 73 s per second of static window
#include "piezoshift/calibration/calibration_procedure.hpp"
#include "piezoshift/rig/procedure_cost.hpp"

namespace piezoshift::calibration {

//! calibrate_with_travel(config, seed, options) at the twin's DAQ rate.
rig::ProcedureCost calibration_cost(const CalibrationOptions& options, double sample_time_s);

//! calibrate_improved() with its default options, then the travel experiment, as
//! `calibrate --controller improved` runs them.
rig::ProcedureCost improved_calibration_cost();

}  // namespace piezoshift::calibration
