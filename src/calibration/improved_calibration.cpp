#include "piezoshift/calibration/improved_calibration.hpp"

namespace piezoshift::calibration {

ImprovedCalibrationOutcome calibrate_improved(const io::ProjectConfig& config,
                                              const control::SemiClosedLoopParams& base,
                                              std::uint64_t seed,
                                              const ImprovedCalibrationOptions& options,
                                              const experiments::Progress& progress) {
  ImprovedCalibrationOutcome out;
  out.static_map = calibrate(config, base, seed, options.paper, progress);
  out.controller = out.static_map.controller;
  return out;
}

}  // namespace piezoshift::calibration
