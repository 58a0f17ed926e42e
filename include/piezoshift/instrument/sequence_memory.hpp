#pragma once
// The memory a phase-shifting measurement holds, estimated from its request before it starts,
// and the bound every front end (`measure`, serve's POST /api/measure) refuses it beyond.
//
//   frames     averages x steps frames, each kept to the end: its counts (camera::Frame, 2 bytes
//              a pixel) and, for the analysis, the same as doubles (frame_maps, 8 bytes a pixel)
//   averages   each average's analysis is kept until they are averaged: its wrapped phase,
//              modulation and surface (doubles) and its valid mask (a byte), 25 bytes a pixel
//   working    one average's analysis under way (unwrapping's edges, the fit of the steps) and the
//              mean surface, its mask and PNGs: kWorkingBytesPerPixel
// The bound: the frames are a frame set as `psi analyze` holds one (doubles), so psi's bound
// applies to them, kMaxFrameSetPixels (2^26 pixels in all: 16 frames of 2048 x 2048, 1024 of
// 256 x 256); and the estimate in all at most kMaxSequenceMemoryBytes. A measurement's hold
// (SequenceParams::hold_s) keeps no frame, and the lock's fit one frame at a time: neither
// adds to it. Before the bound, 100 averages of frame13 on 256 px frames took serve from 120 MB
// to 1.09 GB, and on 512 px frames ended it in std::bad_alloc.
#include <cstdint>
#include <string>

#include "piezoshift/camera/settings.hpp"
#include "piezoshift/instrument/sequence.hpp"

namespace piezoshift::instrument {

inline constexpr std::uint64_t kFrameBytesPerPixel = 2 + 8;
inline constexpr std::uint64_t kAverageBytesPerPixel = 3 * 8 + 1;
inline constexpr std::uint64_t kWorkingBytesPerPixel = 96;
//! The estimate's bound [bytes]: 1 GiB.
inline constexpr std::uint64_t kMaxSequenceMemoryBytes = std::uint64_t{1} << 30;

//! The estimated memory of the measurement p with frames of camera's size [bytes].
std::uint64_t sequence_memory_bytes(const SequenceParams& p, const camera::CameraSettings& camera);

//! "" when the measurement stays within both bounds (see the top), else why not: its frames, its
//! estimate, the bound it crosses and the most averages that fit on this camera.
std::string sequence_memory_problem(const SequenceParams& p, const camera::CameraSettings& camera);

}  // namespace piezoshift::instrument
