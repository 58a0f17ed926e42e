#pragma once
// Aravis's in-process fake camera shown the twin's fringes (`aravis:Fake_1` on `--daq sim`): the
// twin camera renders each exposure from the plate's true motion, and the frame then travels the
// whole aravis: path (software trigger, GenICam stream, buffer pool, pixel unpacking, lost-frame
// checks) before the measurement sees it. So `--camera aravis:Fake_1` and `--camera twin` must
// give the same surface; what differs is only what Aravis did to the pixels.
//
//   trigger(t), observe_plate()   the twin's (it exposes over the loop's time)
//   poll(), wait()                each frame the twin finished is queued for the fake camera's
//                                 fill callback and the fake camera is triggered in software; the
//                                 frame it delivers carries the twin frame's trigger time
// Frames move between the threads by index through lock-free rings (runtime/spsc_ring.hpp); the
// pixels are copied once, by the fill callback on Aravis's stream thread.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "piezoshift/camera/camera.hpp"
#include "piezoshift/runtime/spsc_ring.hpp"

namespace piezoshift::camera {

class TwinFedCamera final : public Camera {
 public:
  //! twin: a twin camera; fake: an aravis: camera on the in-process fake device, unconfigured.
  TwinFedCamera(std::unique_ptr<Camera> twin, std::unique_ptr<Camera> fake);
  ~TwinFedCamera() override;

  void configure(const CameraSettings& settings) override;
  void start() override;
  bool trigger(double loop_time_s) noexcept override { return twin_->trigger(loop_time_s); }
  FrameStatus poll(Frame& frame) noexcept override;
  FrameStatus wait(Frame& frame, double timeout_s) override;
  void stop() noexcept override;
  void observe_plate(const PlatePose& pose) noexcept override { twin_->observe_plate(pose); }

  std::string name() const override { return fake_->name(); }
  const CameraSettings& settings() const override { return fake_->settings(); }
  std::string message() const override;
  std::uint64_t lost_frames() const noexcept override { return fake_->lost_frames(); }

 private:
  // Moves every frame the twin has finished to the fake camera; kError when the twin failed.
  FrameStatus pump() noexcept;
  FrameStatus take(Frame& frame, FrameStatus fake_status) noexcept;

  std::unique_ptr<Camera> twin_;
  std::unique_ptr<Camera> fake_;
  std::vector<std::vector<std::uint16_t>> slots_;  // a twin frame waiting for the fill callback
  std::unique_ptr<runtime::SpscRing<std::uint32_t>> ready_;  // pump -> fill: slots to show
  std::unique_ptr<runtime::SpscRing<std::uint32_t>> free_;   // fill -> pump: slots shown
  std::vector<double> trigger_times_;  // the twin frames' trigger times, in order (pump, poll)
  std::size_t times_in_ = 0, times_out_ = 0;
  std::string error_;
};

}  // namespace piezoshift::camera
