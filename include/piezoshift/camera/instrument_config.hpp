#pragma once
// One installation's configuration file read for a measurement: the design, twin and [safety]
// sections as runtime::load_installation_config() reads them, and [camera]
// (camera_config.hpp); then every key nobody read is refused (core::InputError naming the file
// and the key). A command that takes a camera loads its --config through this, so one file
// serves `run`, `serve` and the measurement alike.
#include <string>

#include "piezoshift/camera/camera_config.hpp"
#include "piezoshift/runtime/safety_ranges.hpp"

namespace piezoshift::camera {

struct InstrumentConfig {
  runtime::InstallationConfig installation;
  CameraConfig camera;
};

InstrumentConfig load_instrument_config(const std::string& path);

}  // namespace piezoshift::camera
