// Bindings of the config module: the project's configuration (design and twin) and its TOML file.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <string>

#include "bindings.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/runtime/safety_ranges.hpp"
#include "values.hpp"

namespace piezoshift::python {

void bind_config(py::module_& m) {
  py::class_<ps::config::ProjectConfig>(m, "ProjectConfig")
      .def(py::init<>())
      .PS_RW(ps::config::ProjectConfig, design)
      .PS_RW(ps::config::ProjectConfig, twin);
  // An installation's file may carry [safety] (runtime/safety_ranges.hpp): read and checked here
  // too, so that the same file loads in Python and in the CLI.
  m.def(
      "load_project_config",
      [](const std::string& path) { return ps::runtime::load_installation_config(path).project; },
      py::arg("path"), "Loads a TOML configuration (InputError naming file, key and reason)");
}

}  // namespace piezoshift::python
