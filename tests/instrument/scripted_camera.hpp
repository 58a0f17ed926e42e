#pragma once
// A camera for the sequence's tests (sequence_test.cpp, sample_sequence_test.cpp) whose
// behaviour each test chooses.
#include <string>
#include <vector>

#include "piezoshift/camera/camera.hpp"

namespace piezoshift::instrument {

// A camera that exposes over the loop's time: a trigger is taken when the previous readout is
// over, the exposure's poses are recorded, and its frame (one pixel) is ready once the exposure
// has ended. lose_frame: that frame is reported lost; refuse: no trigger is ever taken.
class ScriptedCamera final : public camera::Camera {
 public:
  int lose_frame = -1;
  bool refuse = false;
  std::vector<std::vector<camera::PlatePose>> exposures;

  void configure(const camera::CameraSettings& s) override { settings_ = s; }
  void start() override {}
  bool trigger(double t) noexcept override {
    if (refuse || t < busy_until_s_ || exposing_)
      return false;
    start_s_ = t;
    exposing_ = true;
    busy_until_s_ = t + settings_.exposure_s + settings_.readout_s;
    exposures.emplace_back();
    return true;
  }
  void observe_plate(const camera::PlatePose& pose) noexcept override {
    if (!exposing_)
      return;
    exposures.back().push_back(pose);
    if (pose.time_s >= start_s_ + settings_.exposure_s - 1e-9) {
      exposing_ = false;
      ready_ = true;
    }
  }
  camera::FrameStatus poll(camera::Frame& f) noexcept override {
    if (!ready_)
      return camera::FrameStatus::kNone;
    ready_ = false;
    f = camera::Frame{};
    f.frame_id = next_id_++;
    f.width_px = f.height_px = 1;
    f.counts = {100};
    f.trigger_time_s = start_s_;
    return static_cast<int>(f.frame_id) == lose_frame ? camera::FrameStatus::kLost
                                                      : camera::FrameStatus::kOk;
  }
  camera::FrameStatus wait(camera::Frame& f, double) override {
    const camera::FrameStatus s = poll(f);
    return s == camera::FrameStatus::kNone ? camera::FrameStatus::kTimeout : s;
  }
  void stop() noexcept override {}
  std::string name() const override { return "scripted"; }
  const camera::CameraSettings& settings() const override { return settings_; }
  std::string message() const override { return refuse ? "refusing" : ""; }
  std::uint64_t lost_frames() const noexcept override { return lose_frame >= 0 ? 1 : 0; }

 private:
  camera::CameraSettings settings_;
  double start_s_ = 0.0;
  double busy_until_s_ = 0.0;
  bool exposing_ = false;
  bool ready_ = false;
  std::uint64_t next_id_ = 0;
};

}  // namespace piezoshift::instrument
