#pragma once
// The plant a diagnostic runs on, by name: "default" (the built-in twin), a plant of
// configs/plants/ ("payload" for configs/plants/payload.toml), or an absolute path to a TOML.
#include <string>

#include "piezoshift/config/project_config.hpp"
#include "test_paths.hpp"

namespace piezoshift::testing {

inline config::ProjectConfig plant_by_name(const std::string& name) {
  if (name == "default")
    return {};
  if (!name.empty() && name[0] == '/')
    return config::load_project_config(name);
  return config::load_project_config(source_dir() + "/configs/plants/" + name + ".toml");
}

}  // namespace piezoshift::testing
