#include "piezoshift/camera/camera.hpp"

namespace piezoshift::camera {

const char* to_string(FrameStatus status) noexcept {
  switch (status) {
    case FrameStatus::kOk:
      return "ok";
    case FrameStatus::kNone:
      return "none";
    case FrameStatus::kTimeout:
      return "timeout";
    case FrameStatus::kLost:
      return "lost";
    case FrameStatus::kError:
      return "error";
  }
  return "unknown";
}

int bit_depth(PixelFormat format) noexcept {
  switch (format) {
    case PixelFormat::kMono8:
      return 8;
    case PixelFormat::kMono12:
      return 12;
    case PixelFormat::kMono16:
      return 16;
  }
  return 16;
}

const char* to_string(PixelFormat format) noexcept {
  switch (format) {
    case PixelFormat::kMono8:
      return "Mono8";
    case PixelFormat::kMono12:
      return "Mono12";
    case PixelFormat::kMono16:
      return "Mono16";
  }
  return "unknown";
}

}  // namespace piezoshift::camera
