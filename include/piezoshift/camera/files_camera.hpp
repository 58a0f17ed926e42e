#pragma once
// The files camera (`files:DIR`): recorded frames replayed, for offline re-analysis and tests.
//
//   constructor   DIR must be a directory holding at least one *.png (core::InputError naming
//                 it otherwise); the files are taken in name order (frame_000.png, frame_001.png,
//                 ...: zero-padded names sort as numbers), at most psi::kMaxFrames of them
//   configure()   decodes every file through psi's PNG reader within psi's frame-set bounds
//                 (docs/safety.md: 64 files, 2^26 pixels in all, the pixels refused once the
//                 first file gives the size) and refuses, naming the file, one whose size is not
//                 width_px x height_px, an 8-bit PNG for Mono12/Mono16, a 16-bit PNG for Mono8,
//                 or a count above 2^bits - 1 (a Mono12 frame holds 0..4095)
//   trigger(t)    the next file becomes the next frame; trigger_time_s = t, device timestamp 0
//                 (recorded frames carry no device clock)
//   poll()/wait() the frames in trigger order; a trigger beyond the last file gives kError for
//                 that frame id with a message naming DIR and its file count: a replay never
//                 ends as a silently short sequence
//
// Threads: trigger() from one thread, poll()/wait() from one thread (counters are atomic).
// poll() copies a file's counts into the caller's Frame (it allocates when the Frame's buffer is
// smaller; not for the loop's thread).
#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "piezoshift/camera/camera.hpp"

namespace piezoshift::camera {

class FilesCamera final : public Camera {
 public:
  //! Lists DIR's PNG files (decoded at configure()).
  explicit FilesCamera(const std::string& dir);

  void configure(const CameraSettings& settings) override;
  //! The replay restarts at the first file.
  void start() override;
  bool trigger(double loop_time_s) noexcept override;
  FrameStatus poll(Frame& frame) noexcept override;
  FrameStatus wait(Frame& frame, double timeout_s) override;
  void stop() noexcept override;

  std::string name() const override { return "files:" + dir_; }
  const CameraSettings& settings() const override { return settings_; }
  std::string message() const override;
  std::uint64_t lost_frames() const noexcept override { return 0; }

  //! The files in replay order.
  const std::vector<std::string>& files() const noexcept { return files_; }

 private:
  std::string dir_;
  std::vector<std::string> files_;
  std::vector<std::vector<std::uint16_t>> counts_;  // one per file, after configure()
  std::vector<double> trigger_times_s_;             // one per file
  CameraSettings settings_;
  bool configured_ = false;
  std::atomic<bool> started_{false};
  std::atomic<std::uint64_t> triggered_{0};  // written by trigger()
  std::uint64_t delivered_ = 0;              // poll()'s
  std::atomic<bool> refused_{false};
  enum class Failure : std::uint8_t { kNone, kRanOut, kNoMemory };
  std::atomic<Failure> failure_{Failure::kNone};  // of the frame error_frame_, for message()
  std::atomic<std::uint64_t> error_frame_{0};
};

}  // namespace piezoshift::camera
