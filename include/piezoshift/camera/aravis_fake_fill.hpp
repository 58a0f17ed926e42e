#pragma once
// Hands Aravis's in-process fake camera (`aravis:Fake_1`) the image each frame should hold, so the
// whole aravis: path (GenICam features, stream, buffer pool, pixel unpacking, lost-frame checks)
// carries known pixels: a test asserts frames pixel for pixel, and `measure` feeds it the twin's
// fringes to compare `--camera aravis:Fake_1` with `--camera twin`.
//
// The fake camera calls its fill-pattern callback on its stream thread for every frame it
// produces; fake_fill_with() installs one that asks `fill` for counts (0 .. 2^bits - 1, row-major,
// the configured size) and writes them in the configured pixel format (Mono8 one byte, Mono12 and
// Mono16 16-bit little endian), saturating counts above the format's range as a sensor would.
#include <cstdint>
#include <functional>
#include <span>

#include "piezoshift/camera/camera.hpp"

namespace piezoshift::camera {

struct FakeFillFrame {
  std::uint64_t index = 0;            //!< 0, 1, ... frames filled since fake_fill_with()
  std::uint64_t device_frame_id = 0;  //!< the fake camera's own (16-bit, wrapping) frame id
  int width_px = 0;
  int height_px = 0;
  PixelFormat format = PixelFormat::kMono8;
  double exposure_s = 0.0;  //!< the fake camera's ExposureTime register
};

//! Called on the fake camera's stream thread; fills counts (width_px * height_px). An exception
//! it throws turns that frame into kError.
using FakeFill = std::function<void(const FakeFillFrame& frame, std::span<std::uint16_t> counts)>;

//! camera must be an `aravis:` camera configured on the in-process fake device ("Fake_1") and
//! not started; otherwise throws core::InputError saying which. An empty fill restores the fake
//! camera's own diagonal ramp.
void fake_fill_with(Camera& camera, FakeFill fill);

}  // namespace piezoshift::camera
