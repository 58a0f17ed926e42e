#pragma once
// The aravis:ID camera's class, shared by its two halves: aravis_camera.cpp (configure, start,
// stop and the loop's side) and aravis_stream.cpp (Aravis's stream thread and the fake camera's
// fill). Private to the camera module; only these two files include <arv.h>.
#include <arv.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "piezoshift/camera/aravis_fake_fill.hpp"
#include "piezoshift/camera/camera.hpp"
#include "piezoshift/runtime/spsc_ring.hpp"

namespace piezoshift::camera {
namespace aravis_detail {

inline ArvPixelFormat arv_format(PixelFormat format) noexcept {
  switch (format) {
    case PixelFormat::kMono8:
      return ARV_PIXEL_FORMAT_MONO_8;
    case PixelFormat::kMono12:
      return ARV_PIXEL_FORMAT_MONO_12;
    case PixelFormat::kMono16:
      return ARV_PIXEL_FORMAT_MONO_16;
  }
  return ARV_PIXEL_FORMAT_MONO_16;
}

inline std::size_t bytes_per_pixel(PixelFormat format) noexcept {
  return format == PixelFormat::kMono8 ? 1 : 2;
}

//! What the stream thread hands the loop thread: a frame in a pool slot, or a loss or failure.
struct FrameEvent {
  FrameStatus status = FrameStatus::kNone;
  std::uint32_t slot = 0;        //!< kOk: slots_[slot] holds the frame
  std::uint64_t frame_id = 0;    //!< kLost: the id the missing frame had
  const char* reason = nullptr;  //!< kLost, kError: static text for message()
};

}  // namespace aravis_detail

class AravisCamera final : public Camera {
 public:
  explicit AravisCamera(const std::string& id);
  ~AravisCamera() override;
  AravisCamera(const AravisCamera&) = delete;
  AravisCamera& operator=(const AravisCamera&) = delete;

  void configure(const CameraSettings& settings) override;
  void start() override;
  bool trigger(double loop_time_s) noexcept override;
  FrameStatus poll(Frame& frame) noexcept override;
  FrameStatus wait(Frame& frame, double timeout_s) override;
  void stop() noexcept override;
  std::string name() const override { return name_; }
  const CameraSettings& settings() const override { return settings_; }
  std::string message() const override;
  std::uint64_t lost_frames() const noexcept override {
    return lost_frames_.load(std::memory_order_relaxed);
  }

  void set_fake_fill(FakeFill fill);

 private:
  // configure()
  [[noreturn]] void refuse(const std::string& feature, const std::string& why);
  void open();
  void apply_pixel_format(PixelFormat format);
  void apply_region(int width_px, int height_px);
  void apply_exposure(double exposure_s);
  void apply_gain(double gain_dB);
  void apply_trigger(TriggerSource source);
  void set_enum(const char* feature, const std::string& value);
  // start() / stop()
  void allocate_rings();
  bool is_loopback_gv() const;
  void open_stream();
  void warm_up_stream();
  void release_stream() noexcept;
  void trigger_thread_main();
  // stream thread
  static void stream_callback(void* user, ArvStreamCallbackType type, ArvBuffer* buffer);
  static void fake_fill_callback(ArvBuffer* buffer, void* user, guint32 exposure_us, guint32 gain,
                                 ArvPixelFormat format);
  void on_buffer_done() noexcept;
  void check_buffer(ArvBuffer* buffer) noexcept;
  std::uint64_t missing_before(std::uint64_t device_id, bool trusted) noexcept;
  void publish_frame(ArvBuffer* buffer, std::uint64_t frame_id) noexcept;
  void publish_lost(std::uint64_t frame_id, const char* reason) noexcept;
  void publish(const aravis_detail::FrameEvent& event) noexcept;
  double next_trigger_time() noexcept;
  void recycle(ArvBuffer* buffer) noexcept;
  void fill_fake_buffer(ArvBuffer* buffer, guint32 exposure_us, ArvPixelFormat format) noexcept;
  void set_message(const std::string& text);

  std::string id_;    // as arv_camera_new() takes it
  std::string name_;  // "aravis:ID"
  std::string trigger_line_ = "Line0";
  CameraSettings settings_;
  bool configured_ = false;
  ArvCamera* camera_ = nullptr;
  ArvStream* stream_ = nullptr;
  bool is_fake_ = false;  // Aravis's in-process fake device
  bool gated_ = false;    // software trigger emulated by queuing one buffer per trigger
  std::size_t buffer_bytes_ = 0;
  std::size_t image_bytes_ = 0;
  std::vector<ArvBuffer*> buffers_;  // the pool, ours to free after the stream is gone
  std::atomic<bool> started_{false};
  std::atomic<bool> stream_live_{false};  // callbacks act only while true

  // Rings (allocated by start(); see the comment at the top of aravis_camera.cpp).
  std::vector<Frame> slots_;
  std::unique_ptr<runtime::SpscRing<aravis_detail::FrameEvent>> events_;  // stream thread -> poll
  std::unique_ptr<runtime::SpscRing<std::uint32_t>> free_slots_;          // poll -> stream thread
  std::unique_ptr<runtime::SpscRing<double>> requests_;       // trigger() -> trigger thread
  std::unique_ptr<runtime::SpscRing<double>> trigger_times_;  // trigger thread -> stream thread
  std::unique_ptr<runtime::SpscRing<ArvBuffer*>>
      idle_buffers_;  // gated: stream thread -> trigger thread
  std::thread trigger_thread_;
  std::atomic<std::uint32_t> trigger_signal_{0};
  std::atomic<bool> trigger_running_{false};

  // Stream thread's own state.
  bool have_last_id_ = false;
  std::uint64_t last_device_id_ = 0;
  std::uint64_t last_frame_id_ = 0;  // unwrapped
  guint64 failures_seen_ = 0;
  guint64 underruns_seen_ = 0;
  std::uint64_t counter_only_lost_ = 0;  // lost on the stream's counters, no id gap seen yet
  std::int64_t spare_slot_ = -1;         // a slot taken but not published (events_ full)

  // Fake fill (set while stopped; read on the fake camera's stream thread).
  FakeFill fake_fill_;
  std::vector<std::uint16_t> fill_counts_;
  std::uint64_t fill_index_ = 0;
  std::atomic<const char*> fill_error_{nullptr};

  // Losses the events ring had no room for, reported first by poll().
  std::atomic<std::uint64_t> overflow_lost_{0};
  std::atomic<std::uint64_t> overflow_last_id_{0};
  std::uint64_t overflow_reported_ = 0;
  std::atomic<std::uint64_t> lost_frames_{0};

  // message(): real-time paths store a static text, the others a string under the mutex.
  std::atomic<const char*> rt_message_{nullptr};
  mutable std::mutex message_mutex_;
  std::string message_;
};

}  // namespace piezoshift::camera
