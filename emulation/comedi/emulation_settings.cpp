#include "emulation_settings.hpp"

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/config_file.hpp"

namespace piezoshift::emulation {

EmulationSettings load_emulation_settings(const char* path) {
  EmulationSettings s;
  if (path == nullptr || *path == '\0')
    return s;
  const io::ConfigFile file = io::ConfigFile::load(path);
  s.source = path;
  const io::ConfigSection board = file.section("board");
  board.read("device", s.device);
  board.read("model", s.model);
  board.read("calibrated", s.calibrated);
  board.read("ao_reference_V", s.ao_reference_V, core::Bounds::closed(1.0, 10.0));
  const io::ConfigSection twin = file.section("twin");
  twin.read("config", s.config);
  twin.read("seed", s.seed, core::Bounds::closed(0, 9.2e18));
  twin.read("clock", s.clock);
  twin.read("step_s", s.step_s, core::Bounds::closed(1e-5, 1e-2));
  const io::ConfigSection faults = file.section("faults");
  const core::Bounds at = core::Bounds::closed(0.0, 1e6);
  faults.read("ai_timeout_at_s", s.ai_timeout_at_s, at);
  faults.read("ao_busy_at_s", s.ao_busy_at_s, at);
  faults.read("io_error_at_s", s.io_error_at_s, at);
  faults.read("ai_open_at_s", s.ai_open_at_s, at);
  faults.read("ai_open_channel", s.ai_open_channel, core::Bounds::closed(0, 31));
  const io::ConfigSection record = file.section("record");
  record.read("json", s.record);
  record.read("csv", s.series);
  record.read("csv_period_s", s.series_period_s, core::Bounds::closed(1e-4, 10.0));
  const io::ConfigSection ifm = file.section("interferometer");
  ifm.read("log_folder", s.log_folder);
  ifm.read("log_period_s", s.log_period_s, core::Bounds::closed(1e-3, 1.0));
  file.reject_unknown();
  const auto bad = [&](const char* key, const std::string& value, const char* expected) {
    return core::InputError(fmt::format("{}: {} '{}': expected {}", path, key, value, expected));
  };
  if (s.model != "pci-6229" && s.model != "pci-6220")
    throw bad("[board] model", s.model, "pci-6229 or pci-6220");
  if (s.clock != "wall" && s.clock != "transaction")
    throw bad("[twin] clock", s.clock, "wall or transaction");
  if (s.device.empty())
    throw bad("[board] device", s.device, "a path");
  return s;
}

}  // namespace piezoshift::emulation
