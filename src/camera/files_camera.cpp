#include "piezoshift/camera/files_camera.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <thread>

#include <fmt/core.h>

#include "piezoshift/camera/camera_config.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/psi/frame_set.hpp"
#include "piezoshift/psi/png_image.hpp"

namespace piezoshift::camera {

namespace fs = std::filesystem;

namespace {

// Why the entry at path cannot be a frame ("" when it is a regular file, through links).
std::string not_a_frame(const fs::path& path) {
  std::error_code ec;
  const bool link = fs::is_symlink(fs::symlink_status(path, ec));
  const fs::file_status st = fs::status(path, ec);
  if (ec)
    return link ? fmt::format("a link that does not lead to a file ({})", ec.message())
                : fmt::format("cannot be examined ({})", ec.message());
  const char* prefix = link ? "a link to " : "";
  switch (st.type()) {
    case fs::file_type::regular:
      return "";
    case fs::file_type::directory:
      return fmt::format("{}a directory", prefix);
    case fs::file_type::fifo:
      return fmt::format("{}a FIFO (pipe)", prefix);
    case fs::file_type::character:
    case fs::file_type::block:
      return fmt::format("{}a device", prefix);
    case fs::file_type::socket:
      return fmt::format("{}a socket", prefix);
    default:
      return fmt::format("{}not a regular file", prefix);
  }
}

}  // namespace

FilesCamera::FilesCamera(const std::string& dir) : dir_(dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw core::InputError(fmt::format("camera files:{}: not a directory", dir));
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    std::string ext = e.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) {
      return static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
    });
    if (ext != ".png")
      continue;
    // A frame that is not a regular file used to be skipped, shifting every later frame one
    // step: it is refused by name. Links are followed (a link to a recorded frame is a frame);
    // read_input_file checks the opened file again, so a swap after this listing is caught too.
    if (const std::string kind = not_a_frame(e.path()); !kind.empty())
      throw core::InputError(
          fmt::format("camera files:{}: {}: {}; every *.png must be a regular file", dir,
                      e.path().filename().string(), kind));
    files_.push_back(e.path().string());
  }
  if (ec)
    throw core::InputError(fmt::format("camera files:{}: {}", dir, ec.message()));
  if (files_.empty())
    throw core::InputError(fmt::format("camera files:{}: holds no PNG file", dir));
  // The count first, before anything is decoded (psi/frame_set.hpp's order).
  if (files_.size() > psi::kMaxFrames)
    throw core::InputError(
        fmt::format("camera files:{}: {} PNG files, at most {} are replayed "
                    "(docs/safety.md)",
                    dir, files_.size(), psi::kMaxFrames));
  std::sort(files_.begin(), files_.end());
}

void FilesCamera::configure(const CameraSettings& s) {
  stop();
  configured_ = false;
  if (std::string p = camera_settings_problem(s); !p.empty())
    throw core::InputError(fmt::format("camera files:{}: {}", dir_, p));
  const std::uint64_t pixels = static_cast<std::uint64_t>(s.width_px) *
                               static_cast<std::uint64_t>(s.height_px) * files_.size();
  if (pixels > psi::kMaxFrameSetPixels)
    throw core::InputError(fmt::format(
        "camera files:{}: {} frames of {} x {} pixels are {} pixels, at most {} are read "
        "(docs/safety.md)",
        dir_, files_.size(), s.width_px, s.height_px, pixels, psi::kMaxFrameSetPixels));
  const int bits = bit_depth(s.format);
  const double top = std::ldexp(1.0, bits) - 1.0;
  std::vector<std::vector<std::uint16_t>> counts;
  counts.reserve(files_.size());
  for (const std::string& path : files_) {
    // The size is checked against the settings before the next file is decoded, so the pixels
    // held never exceed the bound above.
    const psi::GrayImage g = psi::read_png_gray(path);
    if (g.counts.width != s.width_px || g.counts.height != s.height_px)
      throw core::InputError(
          fmt::format("{}: {} x {} pixels, but camera.width_px x height_px is "
                      "{} x {}",
                      path, g.counts.width, g.counts.height, s.width_px, s.height_px));
    if ((bits == 8) != (g.bit_depth == 8))
      throw core::InputError(fmt::format("{}: a {}-bit PNG, but camera.pixel_format is {}", path,
                                         g.bit_depth, to_string(s.format)));
    std::vector<std::uint16_t>& c = counts.emplace_back(g.counts.size());
    for (std::size_t p = 0; p < g.counts.size(); ++p) {
      const double v = g.counts.v[p];
      if (v > top)
        throw core::InputError(
            fmt::format("{}: pixel ({}, {}) = {} counts, above {} (camera.pixel_format is {})",
                        path, p % static_cast<std::size_t>(s.width_px),
                        p / static_cast<std::size_t>(s.width_px), v, top, to_string(s.format)));
      c[p] = static_cast<std::uint16_t>(v);
    }
  }
  counts_ = std::move(counts);
  trigger_times_s_.assign(files_.size(), 0.0);
  settings_ = s;
  configured_ = true;
}

void FilesCamera::start() {
  if (!configured_)
    throw core::InputError(fmt::format("camera files:{}: start() before configure()", dir_));
  triggered_ = 0;
  delivered_ = 0;
  refused_ = false;
  failure_ = Failure::kNone;
  started_.store(true, std::memory_order_release);
}

void FilesCamera::stop() noexcept {
  started_.store(false, std::memory_order_release);
}

bool FilesCamera::trigger(double t) noexcept {
  if (!started_.load(std::memory_order_acquire)) {
    refused_.store(true, std::memory_order_release);
    return false;
  }
  const std::uint64_t k = triggered_.load(std::memory_order_relaxed);
  if (k < trigger_times_s_.size())
    trigger_times_s_[k] = t;
  triggered_.store(k + 1, std::memory_order_release);  // publishes the time
  refused_.store(false, std::memory_order_release);
  return true;
}

FrameStatus FilesCamera::poll(Frame& frame) noexcept {
  if (!started_.load(std::memory_order_acquire) ||
      delivered_ >= triggered_.load(std::memory_order_acquire))
    return FrameStatus::kNone;
  const std::uint64_t k = delivered_++;
  frame.frame_id = k;
  frame.width_px = settings_.width_px;
  frame.height_px = settings_.height_px;
  frame.format = settings_.format;
  frame.exposure_s = settings_.exposure_s;
  frame.device_timestamp_ns = 0;
  frame.system_timestamp_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                                  std::chrono::steady_clock::now().time_since_epoch())
                                  .count();
  if (k >= counts_.size()) {
    frame.counts.clear();  // no stale image behind an error (keeps the capacity)
    frame.trigger_time_s = 0.0;
    error_frame_.store(k, std::memory_order_relaxed);
    failure_.store(Failure::kRanOut, std::memory_order_release);
    return FrameStatus::kError;
  }
  frame.trigger_time_s = trigger_times_s_[k];
  try {
    frame.counts = counts_[k];
  } catch (...) {  // std::bad_alloc: the frame did not arrive
    frame.counts.clear();
    error_frame_.store(k, std::memory_order_relaxed);
    failure_.store(Failure::kNoMemory, std::memory_order_release);
    return FrameStatus::kError;
  }
  return FrameStatus::kOk;
}

FrameStatus FilesCamera::wait(Frame& frame, double timeout_s) {
  return poll_until(*this, frame, timeout_s);
}

std::string FilesCamera::message() const {
  const Failure failure = failure_.load(std::memory_order_acquire);
  if (failure == Failure::kNoMemory)
    return fmt::format("camera files:{}: frame {}: no memory to copy it", dir_,
                       error_frame_.load(std::memory_order_relaxed));
  if (failure == Failure::kRanOut)
    return fmt::format(
        "camera files:{}: frame {} was triggered but the directory holds only {} "
        "PNG file(s) ({} .. {}); the recorded sequence ran out",
        dir_, error_frame_.load(std::memory_order_relaxed), files_.size(),
        fs::path(files_.front()).filename().string(), fs::path(files_.back()).filename().string());
  if (refused_.load(std::memory_order_acquire))
    return fmt::format("camera files:{}: trigger refused: not started", dir_);
  return {};
}

}  // namespace piezoshift::camera
