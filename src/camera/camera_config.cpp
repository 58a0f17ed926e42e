#include "piezoshift/camera/camera_config.hpp"

#include <cstdint>
#include <type_traits>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"

namespace piezoshift::camera {

namespace {

// The first problem of the visited values (ints and doubles alike).
template <typename Config>
std::string first_problem(const Config& c) {
  std::string problem;
  visit_camera_values(
      c, [&](const char* section, const char* key, const auto& value, core::Bounds bounds) {
        if (problem.empty())
          problem = core::range_problem(fmt::format("{}.{}", section, key),
                                        static_cast<double>(value), bounds);
      });
  return problem;
}

}  // namespace

std::string camera_config_problem(const CameraConfig& config) {
  return first_problem(config);
}

std::string camera_settings_problem(const CameraSettings& settings) {
  // The settings' keys of the one list; the sensor's keep their (valid) defaults.
  CameraConfig c;
  c.settings = settings;
  return first_problem(c);
}

psi::CameraParams sensor_params(const CameraConfig& config) {
  psi::CameraParams p = config.sensor;
  p.exposure_s = config.settings.exposure_s;
  p.bit_depth = bit_depth(config.settings.format);
  return p;
}

double max_frame_rate_Hz(const CameraSettings& s) noexcept {
  return 1.0 / (s.exposure_s + s.readout_s);
}

bool parse_pixel_format(std::string_view name, PixelFormat& format) noexcept {
  for (PixelFormat f : {PixelFormat::kMono8, PixelFormat::kMono12, PixelFormat::kMono16})
    if (name == to_string(f)) {
      format = f;
      return true;
    }
  return false;
}

void read_camera_section(const io::ConfigFile& file, CameraConfig& config) {
  const io::ConfigSection s = file.section("camera");
  visit_camera_values(config, [&](const char*, const char* key, auto& value, core::Bounds bounds) {
    if constexpr (std::is_same_v<std::remove_reference_t<decltype(value)>, int>) {
      if (std::int64_t v = 0; s.read(key, v, bounds))
        value = static_cast<int>(v);  // within bounds, so within int
    } else {
      s.read(key, value, bounds);
    }
  });
  if (std::string name;
      s.read("pixel_format", name) && !parse_pixel_format(name, config.settings.format))
    throw core::InputError(fmt::format(
        "{}: camera.pixel_format: '{}' is not one of Mono8, Mono12, Mono16", file.source(), name));
  if (std::string name; s.read("trigger", name)) {
    if (name == "software")
      config.settings.trigger = TriggerSource::kSoftware;
    else if (name == "line")
      config.settings.trigger = TriggerSource::kLine;
    else
      throw core::InputError(fmt::format("{}: camera.trigger: '{}' is not one of software, line",
                                         file.source(), name));
  }
  s.read("shot_noise", config.sensor.shot_noise);
  config.sensor = sensor_params(config);
}

}  // namespace piezoshift::camera
