#include "piezoshift/psi/frame_set.hpp"

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/psi/png_image.hpp"

namespace piezoshift::psi {

std::vector<Map> read_frame_set(std::span<const std::string> paths, const FrameSetLimits& limits) {
  if (paths.size() < kMinFrames)
    throw core::InputError(
        fmt::format("psi: {} frame(s) given, at least {} are needed", paths.size(), kMinFrames));
  if (paths.size() > limits.max_frames)
    throw core::InputError(fmt::format("psi: {} frames given, at most {} are read (docs/psi.md)",
                                       paths.size(), limits.max_frames));
  std::vector<Map> frames;
  for (const std::string& p : paths) {
    GrayImage g = read_png_gray(p);
    if (frames.empty()) {
      // Every frame has the first one's size: the whole set's pixels are known now.
      const std::uint64_t pixels = static_cast<std::uint64_t>(g.counts.width) *
                                   static_cast<std::uint64_t>(g.counts.height) * paths.size();
      if (pixels > limits.max_pixels)
        throw core::InputError(fmt::format(
            "{}: {} frames of {} x {} pixels are {} pixels, at most {} are read (docs/psi.md)", p,
            paths.size(), g.counts.width, g.counts.height, pixels, limits.max_pixels));
      frames.reserve(paths.size());
    } else if (g.counts.width != frames[0].width || g.counts.height != frames[0].height) {
      throw core::InputError(fmt::format("{}: {} x {} pixels, but {} is {} x {}", p, g.counts.width,
                                         g.counts.height, paths[0], frames[0].width,
                                         frames[0].height));
    }
    frames.push_back(std::move(g.counts));
  }
  return frames;
}

}  // namespace piezoshift::psi
