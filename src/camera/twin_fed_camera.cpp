#include "piezoshift/camera/twin_fed_camera.hpp"

#include <algorithm>
#include <stdexcept>

#include "piezoshift/camera/aravis_fake_fill.hpp"

namespace piezoshift::camera {

TwinFedCamera::TwinFedCamera(std::unique_ptr<Camera> twin, std::unique_ptr<Camera> fake)
    : twin_(std::move(twin)), fake_(std::move(fake)) {}

TwinFedCamera::~TwinFedCamera() {
  stop();
}

void TwinFedCamera::configure(const CameraSettings& settings) {
  twin_->configure(settings);
  fake_->configure(settings);
  const auto n = static_cast<std::size_t>(std::max(1, settings.buffer_count));
  const auto pixels = static_cast<std::size_t>(settings.width_px) * settings.height_px;
  slots_.assign(n, std::vector<std::uint16_t>(pixels, 0));
  ready_ = std::make_unique<runtime::SpscRing<std::uint32_t>>(n);
  free_ = std::make_unique<runtime::SpscRing<std::uint32_t>>(n);
  for (std::uint32_t i = 0; i < n; ++i)
    free_->try_push(i);
  trigger_times_.assign(n, 0.0);
}

void TwinFedCamera::start() {
  fake_fill_with(*fake_, [this](const FakeFillFrame&, std::span<std::uint16_t> counts) {
    std::uint32_t slot = 0;
    if (!ready_->try_pop(slot))
      throw std::runtime_error("the fake camera made a frame the twin did not render");
    std::copy_n(slots_[slot].begin(), std::min(counts.size(), slots_[slot].size()), counts.begin());
    free_->try_push(slot);
  });
  twin_->start();
  fake_->start();
  times_in_ = times_out_ = 0;
}

FrameStatus TwinFedCamera::pump() noexcept {
  Frame f;
  for (;;) {
    std::uint32_t slot = 0;
    if (!free_->try_pop(slot))
      return FrameStatus::kNone;  // every slot waits for the fake camera: later
    const FrameStatus s = twin_->poll(f);
    if (s != FrameStatus::kOk) {
      free_->try_push(slot);
      if (s != FrameStatus::kNone)
        error_ = "the twin: " + twin_->message();
      return s == FrameStatus::kNone ? FrameStatus::kNone : FrameStatus::kError;
    }
    slots_[slot].swap(f.counts);
    trigger_times_[times_in_++ % trigger_times_.size()] = f.trigger_time_s;
    ready_->try_push(slot);
    if (!fake_->trigger(f.trigger_time_s)) {
      error_ = "the fake camera took no trigger: " + fake_->message();
      return FrameStatus::kError;
    }
  }
}

FrameStatus TwinFedCamera::take(Frame& frame, FrameStatus fake_status) noexcept {
  if (fake_status == FrameStatus::kOk || fake_status == FrameStatus::kLost)
    frame.trigger_time_s = trigger_times_[times_out_++ % trigger_times_.size()];
  return fake_status;
}

FrameStatus TwinFedCamera::poll(Frame& frame) noexcept {
  if (pump() == FrameStatus::kError)
    return FrameStatus::kError;
  return take(frame, fake_->poll(frame));
}

FrameStatus TwinFedCamera::wait(Frame& frame, double timeout_s) {
  return poll_until(*this, frame, timeout_s);
}

void TwinFedCamera::stop() noexcept {
  fake_->stop();
  twin_->stop();
}

std::string TwinFedCamera::message() const {
  return error_.empty() ? fake_->message() : error_;
}

}  // namespace piezoshift::camera
