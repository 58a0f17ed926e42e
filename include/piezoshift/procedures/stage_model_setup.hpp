#pragma once
// The stage as a host drives it (host/stage_model.hpp: poses, travel, open-loop volts) for a
// loop's calibration: `serve`'s GCS interpreter and the loop station (loop_station.hpp) alike.
#include <string>

#include "piezoshift/calibration/loop_calibration.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/host/stage_model.hpp"
#include "piezoshift/runtime/safety_supervisor.hpp"

namespace piezoshift::procedures {

//! The configuration's geometry with the calibration's p, A and travel, the amplifier's gain and
//! the outputs' limit. core::InputError naming calibration_name and config_name when they do not
//! make a stage (a singular A for this geometry, a p not monotonic over the travel).
host::StageModel loop_stage_model(const config::ProjectConfig& config,
                                  const calibration::LoopCalibration& cal,
                                  const runtime::SafetyLimits& safety,
                                  const std::string& calibration_name,
                                  const std::string& config_name);

}  // namespace piezoshift::procedures
