#include "piezoshift/camera/instrument_config.hpp"

#include "piezoshift/config/project_config.hpp"

namespace piezoshift::camera {

InstrumentConfig load_instrument_config(const std::string& path) {
  const io::ConfigFile file = io::ConfigFile::load(path);
  InstrumentConfig c;
  runtime::InstallationConfig& i = c.installation;
  config::read_design_sections(file, i.project.design);
  config::read_twin_sections(file, i.project.design, i.project.twin);
  runtime::read_safety_section(file, i.safety);
  read_camera_section(file, c.camera);
  file.reject_unknown();
  return c;
}

}  // namespace piezoshift::camera
