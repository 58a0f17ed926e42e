#pragma once
// One camera frame as it left the sensor: counts at the sensor's bit depth, with the
// timestamps that tie it to the stage's state during its exposure.
#include <cstdint>
#include <vector>

#include "piezoshift/camera/settings.hpp"

namespace piezoshift::camera {

struct Frame {
  std::uint64_t frame_id = 0;  //!< the device's frame counter (the twin's and files': 0, 1, ...)
  int width_px = 0;
  int height_px = 0;
  PixelFormat format = PixelFormat::kMono12;
  std::vector<std::uint16_t> counts;     //!< row-major, width_px * height_px, 0 .. 2^bits - 1
  double exposure_s = 0.0;               //!< as the device reports it
  double trigger_time_s = 0.0;           //!< loop time of the trigger() that started it
  std::int64_t device_timestamp_ns = 0;  //!< the camera's clock at exposure start (0: none)
  std::int64_t system_timestamp_ns = 0;  //!< the host's monotonic clock when it arrived
};

}  // namespace piezoshift::camera
