#include "piezoshift/camera/camera.hpp"

#include <algorithm>
#include <chrono>
#include <thread>

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

FrameStatus poll_until(Camera& camera, Frame& frame, double timeout_s) {
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                            std::chrono::duration<double>(std::max(0.0, timeout_s)));
  for (;;) {
    if (const FrameStatus s = camera.poll(frame); s != FrameStatus::kNone)
      return s;
    if (std::chrono::steady_clock::now() >= deadline)
      return FrameStatus::kTimeout;
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
}

}  // namespace piezoshift::camera
