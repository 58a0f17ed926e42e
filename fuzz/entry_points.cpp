// The entry points that read files or a command line (the GCS one is gcs_entry.cpp).
#include "entry_points.hpp"

#include <array>
#include <string>
#include <vector>

#include "piezoshift/calibration/calibration_file.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/core/input_error.hpp"
#include "program.hpp"
#include "scratch_file.hpp"

namespace piezoshift::fuzz {
void config_input(std::string_view data) {
  try {
    config::load_project_config(scratch_file("config.toml", data));
  } catch (const core::InputError&) {
  }
}

void calibration_input(std::string_view data) {
  try {
    std::optional<double> z_max, z_min;
    std::optional<control::FringeLockParams> lock;  // the [fringe_lock] reader too
    calibration::load_calibration_file(scratch_file("calibration.toml", data), &z_max, &z_min,
                                       &lock);
  } catch (const core::InputError&) {
  }
}

void csv_input(std::string_view data) {
  const std::string path = scratch_file("data.csv", data);
  static constexpr std::array<std::array<const char*, 2>, 5> kPaths{{{"analyze", "linearity"},
                                                                     {"analyze", "repeatability"},
                                                                     {"analyze", "step"},
                                                                     {"fit", "matrix"},
                                                                     {"fit", "poly"}}};
  // One app per path, built once: 5 apps per input would cost more than the work itself, and
  // each is given the same options every time.
  static Program programs[kPaths.size()];
  for (std::size_t i = 0; i < kPaths.size(); ++i)
    programs[i].run({"piezoshift", kPaths[i][0], kPaths[i][1], "--data", path, "--json"});
}

Outcome command_line(std::string_view data) {
  std::vector<std::string> args{"piezoshift"};
  while (!data.empty()) {
    const std::size_t lf = data.find('\n');
    args.emplace_back(data.substr(0, lf));
    data.remove_prefix(lf == std::string_view::npos ? data.size() : lf + 1);
  }
  return Program().run(args);  // a fresh app: options must not keep an earlier input's
}

void command_line_input(std::string_view data) {
  command_line(data);
}

std::span<const Target> targets() {
  static constexpr std::array<Target, 7> kTargets{{{"config", config_input},
                                                   {"csv", csv_input},
                                                   {"calibration", calibration_input},
                                                   {"gcs", gcs_input},
                                                   {"plot", plot_input},
                                                   {"command_line", command_line_input},
                                                   {"measure_request", measure_request_input}}};
  return kTargets;
}

}  // namespace piezoshift::fuzz
