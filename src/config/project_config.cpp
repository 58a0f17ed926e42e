#include "piezoshift/config/project_config.hpp"

#include <optional>
#include <type_traits>

#include <fmt/core.h>

#include "piezoshift/core/bounds.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/design/design_ranges.hpp"
#include "piezoshift/plant/twin_ranges.hpp"

namespace piezoshift::config {

namespace {

// Reads one value of a ranges list (design_ranges.hpp, twin_ranges.hpp) from section.key.
struct RangedReader {
  const io::ConfigFile& file;

  template <typename T>
  void operator()(const char* section, const char* key, T& value, core::Bounds bounds) const {
    const io::ConfigSection s = file.section(section);
    if constexpr (std::is_same_v<T, std::optional<double>>) {
      if (double v = 0.0; s.read(key, v, bounds))
        value = v;
    } else {
      s.read(key, value, bounds);
    }
  }
};

}  // namespace

void read_design_sections(const io::ConfigFile& file, design::DesignInputs& design) {
  design::visit_design_values(design, RangedReader{file});
  // The geometry involves two keys (one perhaps left at its default); the message names both.
  if (const std::string problem = design::hinge_geometry_problem(design.hinge); !problem.empty())
    throw core::InputError(fmt::format("{}: {}", file.source(), problem));
}

void read_twin_sections(const io::ConfigFile& file, const design::DesignInputs& design,
                        plant::TwinParams& t) {
  plant::visit_twin_values(t, RangedReader{file});
  const io::ConfigSection sgs = file.section("twin.sgs");
  if (std::string shape; sgs.read("nonlinearity_shape", shape)) {
    if (shape == "bow")
      t.sgs.nonlinearity_shape = plant::SgsNonlinearityShape::kBow;
    else if (shape == "s_curve")
      t.sgs.nonlinearity_shape = plant::SgsNonlinearityShape::kSCurve;
    else if (shape == "wave")
      t.sgs.nonlinearity_shape = plant::SgsNonlinearityShape::kWave;
    else
      throw core::InputError(
          fmt::format("{}: twin.sgs.nonlinearity_shape: '{}' is not one of bow, s_curve, wave",
                      file.source(), shape));
  }
  // A switch, not a quantity: read apart from the ranges list.
  file.section("twin.cavity").read("in_fringes", t.cavity.in_fringes);

  // What one key's bounds cannot say (rates that must divide, the contact identification, A).
  if (const std::string problem = plant::twin_params_problem(design, t); !problem.empty())
    throw core::InputError(fmt::format("{}: {}", file.source(), problem));
}

ProjectConfig load_project_config(const std::string& path) {
  const io::ConfigFile file = io::ConfigFile::load(path);
  ProjectConfig config;
  read_design_sections(file, config.design);
  read_twin_sections(file, config.design, config.twin);
  file.reject_unknown();
  return config;
}

}  // namespace piezoshift::config
