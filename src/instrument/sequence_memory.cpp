#include "piezoshift/instrument/sequence_memory.hpp"

#include <algorithm>

#include <fmt/core.h>

#include "piezoshift/psi/frame_set.hpp"

namespace piezoshift::instrument {

namespace {

std::uint64_t pixels_of(const camera::CameraSettings& camera) {
  return static_cast<std::uint64_t>(std::max(camera.width_px, 0)) *
         static_cast<std::uint64_t>(std::max(camera.height_px, 0));
}

// Within both bounds with this many averages.
bool fits(const SequenceParams& p, const camera::CameraSettings& camera, int averages) {
  SequenceParams q = p;
  q.averages = averages;
  const std::uint64_t frames = static_cast<std::uint64_t>(averages) * p.steps_rad.size();
  return frames * pixels_of(camera) <= psi::kMaxFrameSetPixels &&
         sequence_memory_bytes(q, camera) <= kMaxSequenceMemoryBytes;
}

}  // namespace

std::uint64_t sequence_memory_bytes(const SequenceParams& p, const camera::CameraSettings& camera) {
  const std::uint64_t px = pixels_of(camera);
  const auto averages = static_cast<std::uint64_t>(std::max(p.averages, 0));
  const std::uint64_t frames = averages * p.steps_rad.size();
  return px *
         (frames * kFrameBytesPerPixel + averages * kAverageBytesPerPixel + kWorkingBytesPerPixel);
}

std::string sequence_memory_problem(const SequenceParams& p, const camera::CameraSettings& camera) {
  if (fits(p, camera, p.averages))
    return {};
  int most = p.averages - 1;
  while (most > 0 && !fits(p, camera, most))
    --most;
  const std::uint64_t frames = static_cast<std::uint64_t>(p.averages) * p.steps_rad.size();
  return fmt::format(
      "{} averages x {} frames of {} x {} px: {} frames, about {} MiB held; the bound is {} frame "
      "pixels in all (psi's frame set, 2^26) and {} MiB: {}",
      p.averages, p.steps_rad.size(), camera.width_px, camera.height_px, frames,
      sequence_memory_bytes(p, camera) >> 20, psi::kMaxFrameSetPixels,
      kMaxSequenceMemoryBytes >> 20,
      most > 0 ? fmt::format("at most {} average{} on this camera", most, most == 1 ? "" : "s")
               : std::string("the camera's frames are too large for one average; a smaller ROI"));
}

}  // namespace piezoshift::instrument
