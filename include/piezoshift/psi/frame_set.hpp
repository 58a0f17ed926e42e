#pragma once
// A frame set read from PNG files (png_image.hpp), bounded before it is decoded: at most
// kMaxFrames files and kMaxFrameSetPixels pixels in all (the frames are held as doubles, 8 bytes a
// pixel: 512 MiB, e.g. 16 frames of 2048 x 2048 or 64 of 1024 x 1024). The count is checked
// before any file is read, the pixels once the first frame gives the size (every frame has it),
// before the others are decoded: 150 copies of one PNG used to end in std::bad_alloc.
// Set-up only; every refusal is core::InputError naming the file or the count and the limit.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "piezoshift/psi/grid.hpp"

namespace piezoshift::psi {

inline constexpr std::size_t kMinFrames = 3;
inline constexpr std::size_t kMaxFrames = 64;
inline constexpr std::uint64_t kMaxFrameSetPixels = std::uint64_t{1} << 26;  // 16 x 2048 x 2048

struct FrameSetLimits {
  std::size_t max_frames = kMaxFrames;
  std::uint64_t max_pixels = kMaxFrameSetPixels;
};

//! The frames in the order given, all of one size, as counts (read_png_gray).
std::vector<Map> read_frame_set(std::span<const std::string> paths,
                                const FrameSetLimits& limits = {});

}  // namespace piezoshift::psi
