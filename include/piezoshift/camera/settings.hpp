#pragma once
// What a measurement asks of a camera (the `[camera]` section and the command line). The twin
// camera's sensor model (full well, read noise, ...) is psi::CameraParams, in the same section.
#include <cstdint>

namespace piezoshift::camera {

enum class PixelFormat : std::uint8_t { kMono8, kMono12, kMono16 };
//! 8, 12 or 16.
int bit_depth(PixelFormat format) noexcept;
//! "Mono8", "Mono12", "Mono16" (GenICam PixelFormat names).
const char* to_string(PixelFormat format) noexcept;

enum class TriggerSource : std::uint8_t {
  kSoftware,  //!< trigger() starts each exposure
  kLine,      //!< a hardware line (the loop's trigger pulse) starts it; trigger() arms nothing
};

struct CameraSettings {
  int width_px = 256;
  int height_px = 256;
  PixelFormat format = PixelFormat::kMono12;
  double exposure_s = 1e-3;
  double gain_dB = 0.0;
  TriggerSource trigger = TriggerSource::kSoftware;
  double readout_s = 0.01;  //!< after an exposure, before the next can start
  int buffer_count = 16;    //!< the stream's buffer pool
};

}  // namespace piezoshift::camera
