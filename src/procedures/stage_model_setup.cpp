#include "piezoshift/procedures/stage_model_setup.hpp"

#include <stdexcept>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"

namespace piezoshift::procedures {

host::StageModel loop_stage_model(const config::ProjectConfig& config,
                                  const calibration::LoopCalibration& cal,
                                  const runtime::SafetyLimits& safety,
                                  const std::string& calibration_name,
                                  const std::string& config_name) {
  try {
    host::StageModelParams mp = host::stage_model_params(config.twin.geometry, cal.params);
    if (cal.travel_z_max_um)
      mp.z_max_um = *cal.travel_z_max_um;
    if (cal.travel_z_min_um)
      mp.z_min_um = *cal.travel_z_min_um;
    mp.amplifier_gain = config.twin.amplifier.gain;
    mp.channel_max_V = safety.output_max_V * mp.amplifier_gain;
    return host::StageModel(mp);
  } catch (const std::invalid_argument& e) {
    // The calibration's A and the config's geometry meet here: name both.
    throw core::InputError(fmt::format("{} with {}: {}", calibration_name, config_name, e.what()));
  }
}

}  // namespace piezoshift::procedures
