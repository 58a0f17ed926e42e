// aravis:ID, a GenICam camera through Aravis 0.8 (docs/camera.md).
//
// Threads and who owns what while acquiring:
//   loop thread      trigger() pushes the loop time onto requests_; poll() pops events_ and
//                    returns slots to free_slots_. Neither takes a lock nor calls Aravis.
//   trigger thread   ours: pops requests_, issues TriggerSoftware (a GVCP/U3V register write that
//                    waits for the device's acknowledge, so never on the loop's thread), and
//                    passes the trigger time to the stream thread through trigger_times_.
//   stream thread    Aravis's: its BUFFER_DONE callback pops the buffer, checks it (status, frame
//                    id gap, the stream's failure and underrun counters), unpacks the pixels into
//                    a free slot, publishes the event and gives the buffer back to the stream.
// Every ring is runtime::SpscRing (one producer, one consumer, wait-free).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "aravis_camera_impl.hpp"
#include "piezoshift/camera/aravis_camera.hpp"
#include "piezoshift/core/input_error.hpp"

namespace piezoshift::camera {
namespace {

using aravis_detail::arv_format;
using aravis_detail::bytes_per_pixel;
using aravis_detail::FrameEvent;
using runtime::SpscRing;

std::size_t power_of_two_at_least(std::size_t n) {
  std::size_t p = 2;
  while (p < n)
    p *= 2;
  return p;
}

//! A GError that frees itself; out() hands Aravis a cleared slot.
class Error {
 public:
  Error() = default;
  Error(const Error&) = delete;
  Error& operator=(const Error&) = delete;
  ~Error() { g_clear_error(&error_); }
  GError** out() noexcept {
    g_clear_error(&error_);
    return &error_;
  }
  explicit operator bool() const noexcept { return error_ != nullptr; }
  std::string text() const { return error_ != nullptr ? error_->message : ""; }

 private:
  GError* error_ = nullptr;
};

//! Takes a NULL-terminated or counted string array from an arv_*_dup_* call (the strings belong
//! to the GenICam document; only the array is ours).
std::vector<std::string> take_strings(const char** list, guint n) {
  std::vector<std::string> out;
  for (guint i = 0; list != nullptr && i < n; ++i)
    out.emplace_back(list[i] != nullptr ? list[i] : "");
  g_free(static_cast<void*>(list));
  return out;
}

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& item : items)
    out += (out.empty() ? "" : ", ") + item;
  return out.empty() ? "none" : out;
}

bool contains(const std::vector<std::string>& items, const std::string& item) {
  return std::find(items.begin(), items.end(), item) != items.end();
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// configure()

AravisCamera::AravisCamera(const std::string& id) : id_(id), name_("aravis:" + id) {
  const auto at = id_.rfind('@');
  if (at != std::string::npos && id_.compare(at + 1, 4, "Line") == 0) {
    trigger_line_ = id_.substr(at + 1);
    id_.resize(at);
  }
}

AravisCamera::~AravisCamera() {
  stop();
  if (camera_ != nullptr && is_fake_) {
    ArvFakeCamera* fake =
        arv_fake_device_get_fake_camera(ARV_FAKE_DEVICE(arv_camera_get_device(camera_)));
    arv_fake_camera_set_fill_pattern(fake, nullptr, nullptr);
  }
  g_clear_object(&camera_);
}

void AravisCamera::refuse(const std::string& feature, const std::string& why) {
  const std::string text = name_ + ": " + feature + ": " + why;
  set_message(text);
  throw core::InputError(text);
}

void AravisCamera::set_message(const std::string& text) {
  std::lock_guard lock(message_mutex_);
  message_ = text;
  rt_message_.store(nullptr, std::memory_order_relaxed);
}

std::string AravisCamera::message() const {
  if (const char* rt = rt_message_.load(std::memory_order_acquire); rt != nullptr)
    return name_ + ": " + rt;
  std::lock_guard lock(message_mutex_);
  return message_;
}

void AravisCamera::open() {
  if (camera_ != nullptr)
    return;
  // The in-process fake camera is hidden unless its interface is enabled; only for ids that
  // name it, so that "" still means the first real camera.
  if (id_.rfind("Fake", 0) == 0)
    arv_enable_interface("Fake");
  Error error;
  camera_ = arv_camera_new(id_.empty() ? nullptr : id_.c_str(), error.out());
  if (camera_ == nullptr) {
    std::vector<std::string> found;
    arv_update_device_list();
    for (unsigned i = 0; i < arv_get_n_devices(); ++i)
      found.emplace_back(arv_get_device_id(i));
    refuse("device", "cannot open " +
                         (id_.empty() ? std::string("the first camera") : "'" + id_ + "'") + " (" +
                         (error ? error.text() : "no camera found") +
                         "); cameras Aravis sees: " + join(found));
  }
  is_fake_ = ARV_IS_FAKE_DEVICE(arv_camera_get_device(camera_));
}

void AravisCamera::set_enum(const char* feature, const std::string& value) {
  Error error;
  arv_camera_set_string(camera_, feature, value.c_str(), error.out());
  if (error)
    refuse(feature, "cannot set " + value + " (" + error.text() + ")");
}

void AravisCamera::apply_pixel_format(PixelFormat format) {
  Error error;
  guint n = 0;
  const char** list = arv_camera_dup_available_pixel_formats_as_strings(camera_, &n, error.out());
  const auto offered = take_strings(list, n);  // n is set by the call above
  if (error)
    refuse("PixelFormat", "cannot list the formats (" + error.text() + ")");
  // Refused, never converted: a Mono12 measurement silently taken in Mono8 loses 4 bits.
  if (!contains(offered, to_string(format)))
    refuse("PixelFormat", std::string(to_string(format)) +
                              " is not offered by the device (it offers " + join(offered) + ")");
  arv_camera_set_pixel_format(camera_, arv_format(format), error.out());
  if (error || arv_camera_get_pixel_format(camera_, nullptr) != arv_format(format))
    refuse("PixelFormat",
           std::string("cannot set ") + to_string(format) + " (" + error.text() + ")");
}

void AravisCamera::apply_region(int width_px, int height_px) {
  Error error;
  gint min_w = 0, max_w = 0, min_h = 0, max_h = 0;
  arv_camera_get_width_bounds(camera_, &min_w, &max_w, error.out());
  if (!error)
    arv_camera_get_height_bounds(camera_, &min_h, &max_h, error.out());
  if (error)
    refuse("Width/Height", "cannot read the bounds (" + error.text() + ")");
  const gint inc_w = std::max(1, arv_camera_get_width_increment(camera_, nullptr));
  const gint inc_h = std::max(1, arv_camera_get_height_increment(camera_, nullptr));
  auto check = [&](const char* feature, int value, gint lo, gint hi, gint inc) {
    if (value < lo || value > hi || value % inc != 0)
      refuse(feature, std::to_string(value) + " px is outside the device's " + std::to_string(lo) +
                          " .. " + std::to_string(hi) + " px in steps of " + std::to_string(inc));
  };
  check("Width", width_px, min_w, max_w, inc_w);
  check("Height", height_px, min_h, max_h, inc_h);
  // Centred on the sensor where the device has offsets: the pupil is usually imaged there.
  gint x = 0, y = 0;
  if (arv_camera_is_region_offset_available(camera_, nullptr)) {
    gint sensor_w = 0, sensor_h = 0;
    arv_camera_get_sensor_size(camera_, &sensor_w, &sensor_h, nullptr);
    const gint inc_x = std::max(1, arv_camera_get_x_offset_increment(camera_, nullptr));
    const gint inc_y = std::max(1, arv_camera_get_y_offset_increment(camera_, nullptr));
    x = std::max(0, (sensor_w - width_px) / 2) / inc_x * inc_x;
    y = std::max(0, (sensor_h - height_px) / 2) / inc_y * inc_y;
  }
  arv_camera_set_region(camera_, x, y, width_px, height_px, error.out());
  gint got_x = 0, got_y = 0, got_w = 0, got_h = 0;
  if (!error)
    arv_camera_get_region(camera_, &got_x, &got_y, &got_w, &got_h, error.out());
  if (error || got_w != width_px || got_h != height_px)
    refuse("Width/Height", "cannot set " + std::to_string(width_px) + " x " +
                               std::to_string(height_px) + " px (the device has " +
                               std::to_string(got_w) + " x " + std::to_string(got_h) + "; " +
                               error.text() + ")");
}

void AravisCamera::apply_exposure(double exposure_s) {
  Error error;
  if (!arv_camera_is_exposure_time_available(camera_, nullptr))
    refuse("ExposureTime", "the device has no exposure time");
  if (arv_camera_is_exposure_auto_available(camera_, nullptr))
    arv_camera_set_exposure_time_auto(camera_, ARV_AUTO_OFF, nullptr);
  double min_us = 0.0, max_us = 0.0;
  arv_camera_get_exposure_time_bounds(camera_, &min_us, &max_us, error.out());
  const double us = exposure_s * 1e6;
  if (!error && (us < min_us || us > max_us))
    refuse("ExposureTime", std::to_string(us) + " us is outside the device's " +
                               std::to_string(min_us) + " .. " + std::to_string(max_us) + " us");
  arv_camera_set_exposure_time(camera_, us, error.out());
  if (error)
    refuse("ExposureTime", "cannot set " + std::to_string(us) + " us (" + error.text() + ")");
  settings_.exposure_s = arv_camera_get_exposure_time(camera_, nullptr) * 1e-6;
}

void AravisCamera::apply_gain(double gain_dB) {
  Error error;
  if (!arv_camera_is_gain_available(camera_, nullptr)) {
    if (gain_dB != 0.0)
      refuse("Gain", "the device has no gain, and " + std::to_string(gain_dB) + " dB was asked");
    return;
  }
  if (arv_camera_is_gain_auto_available(camera_, nullptr))
    arv_camera_set_gain_auto(camera_, ARV_AUTO_OFF, nullptr);
  double lo = 0.0, hi = 0.0;
  arv_camera_get_gain_bounds(camera_, &lo, &hi, error.out());
  if (!error && (gain_dB < lo || gain_dB > hi))
    refuse("Gain", std::to_string(gain_dB) + " is outside the device's " + std::to_string(lo) +
                       " .. " + std::to_string(hi));
  arv_camera_set_gain(camera_, gain_dB, error.out());
  if (error)
    refuse("Gain", "cannot set " + std::to_string(gain_dB) + " (" + error.text() + ")");
  settings_.gain_dB = arv_camera_get_gain(camera_, nullptr);
}

void AravisCamera::apply_trigger(TriggerSource source) {
  const std::string wanted = source == TriggerSource::kSoftware ? "Software" : trigger_line_;
  Error error;
  guint n = 0;
  const char** list = arv_camera_dup_available_trigger_sources(camera_, &n, error.out());
  const auto sources = take_strings(list, n);
  if (error || !contains(sources, wanted))
    refuse("TriggerSource", wanted + " is not offered by the device (it offers " + join(sources) +
                                (error ? "; " + error.text() : std::string()) + ")");
  // Every exposure starts on a trigger: FrameStart triggered, every other trigger off.
  arv_camera_clear_triggers(camera_, error.out());
  if (error)
    refuse("TriggerMode", "cannot switch the triggers off (" + error.text() + ")");
  if (arv_camera_is_feature_available(camera_, "TriggerSelector", nullptr))
    set_enum("TriggerSelector", "FrameStart");
  set_enum("TriggerSource", wanted);
  set_enum("TriggerMode", "On");
  if (source == TriggerSource::kLine &&
      arv_camera_is_feature_available(camera_, "TriggerActivation", nullptr))
    set_enum("TriggerActivation", "RisingEdge");
  arv_camera_set_acquisition_mode(camera_, ARV_ACQUISITION_MODE_CONTINUOUS, error.out());
  if (error)
    refuse("AcquisitionMode", "cannot set Continuous (" + error.text() + ")");
}

void AravisCamera::configure(const CameraSettings& settings) {
  stop();
  configured_ = false;
  if (settings.width_px <= 0 || settings.height_px <= 0)
    refuse("Width/Height", "the size must be positive");
  if (settings.buffer_count < 2 || settings.buffer_count > 1024)
    refuse("buffer_count", std::to_string(settings.buffer_count) + " is outside 2 .. 1024");
  if (!(settings.exposure_s > 0.0))
    refuse("ExposureTime", "the exposure must be positive");
  settings_ = settings;
  open();
  apply_pixel_format(settings.format);  // first: the size bounds can depend on it
  apply_region(settings.width_px, settings.height_px);
  apply_exposure(settings.exposure_s);
  apply_gain(settings.gain_dB);
  apply_trigger(settings.trigger);
  set_message("");
  configured_ = true;
}

void AravisCamera::set_fake_fill(FakeFill fill) {
  if (!configured_ || !is_fake_)
    refuse("fake fill", "needs the in-process fake camera (aravis:Fake_1), configured");
  if (started_.load())
    refuse("fake fill", "cannot change the image while acquiring (stop() first)");
  fake_fill_ = std::move(fill);
  fill_index_ = 0;
  fill_error_.store(nullptr);
  ArvFakeCamera* fake =
      arv_fake_device_get_fake_camera(ARV_FAKE_DEVICE(arv_camera_get_device(camera_)));
  if (fake_fill_)
    arv_fake_camera_set_fill_pattern(fake, &AravisCamera::fake_fill_callback, this);
  else
    arv_fake_camera_set_fill_pattern(fake, nullptr, nullptr);
}

// ---------------------------------------------------------------------------------------------
// start() / stop()

void AravisCamera::allocate_rings() {
  const auto n = static_cast<std::size_t>(settings_.buffer_count);
  slots_.assign(n, Frame{});
  for (auto& slot : slots_)
    slot.counts.resize(static_cast<std::size_t>(settings_.width_px) * settings_.height_px);
  // Room for every slot's frame plus a loss report per buffer in flight, several times over.
  events_ = std::make_unique<SpscRing<FrameEvent>>(
      power_of_two_at_least(std::max<std::size_t>(64, 4 * n)));
  free_slots_ = std::make_unique<SpscRing<std::uint32_t>>(power_of_two_at_least(n));
  for (std::uint32_t i = 0; i < n; ++i)
    free_slots_->try_push(i);
  requests_ = std::make_unique<SpscRing<double>>(256);
  trigger_times_ = std::make_unique<SpscRing<double>>(1024);
  idle_buffers_ = std::make_unique<SpscRing<ArvBuffer*>>(power_of_two_at_least(n));
  have_last_id_ = false;
  counter_only_lost_ = 0;
  spare_slot_ = -1;
  overflow_lost_.store(0);
  overflow_reported_ = 0;
  lost_frames_.store(0);
}

void AravisCamera::start() {
  if (!configured_)
    refuse("start", "configure() first");
  if (started_.load())
    return;
  Error error;
  buffer_bytes_ = arv_camera_get_payload(camera_, error.out());
  image_bytes_ = static_cast<std::size_t>(settings_.width_px) * settings_.height_px *
                 bytes_per_pixel(settings_.format);
  if (error || buffer_bytes_ < image_bytes_)
    refuse("PayloadSize", std::to_string(buffer_bytes_) + " bytes, less than the " +
                              std::to_string(image_bytes_) + " bytes of one image " + error.text());
  // The in-process fake camera ignores TriggerMode: its stream fills any queued buffer at its
  // trigger frequency. Queuing one buffer per trigger makes it behave like a triggered camera.
  // Otherwise (line trigger) it stands for a line pulsed at Aravis's default 25 Hz.
  gated_ = is_fake_ && settings_.trigger == TriggerSource::kSoftware;
  if (is_fake_)
    arv_fake_camera_set_trigger_frequency(
        arv_fake_device_get_fake_camera(ARV_FAKE_DEVICE(arv_camera_get_device(camera_))),
        gated_ ? 1000.0 : 25.0);
  allocate_rings();  // before the stream exists: its thread may call back at once
  open_stream();
  buffers_.clear();
  for (int i = 0; i < settings_.buffer_count; ++i) {
    ArvBuffer* buffer = arv_buffer_new_allocate(buffer_bytes_);
    buffers_.push_back(buffer);
    // Our reference stays in buffers_; the queue that holds a buffer holds one of its own.
    if (gated_)
      idle_buffers_->try_push(ARV_BUFFER(g_object_ref(buffer)));
    else
      arv_stream_push_buffer(stream_, ARV_BUFFER(g_object_ref(buffer)));
  }
  trigger_running_.store(true);
  trigger_thread_ = std::thread([this] { trigger_thread_main(); });
  started_.store(true);
  arv_camera_start_acquisition(camera_, error.out());
  if (error) {
    const std::string why = error.text();
    stop();
    refuse("AcquisitionStart", "cannot start (" + why + ")");
  }
  set_message("");
}

void AravisCamera::open_stream() {
  const bool loopback = is_loopback_gv();
  if (loopback) {
    // Run as root (CAP_NET_RAW), Aravis receives GigE Vision through a packet socket, which sees
    // none of a loopback camera's packets (arv-fake-gv-camera-0.8 on 127.0.0.1): a UDP socket.
    // Loopback's MTU is 64 KiB: 8 KiB packets, fewer to lose.
    arv_camera_gv_set_stream_options(camera_, ARV_GV_STREAM_OPTION_PACKET_SOCKET_DISABLED);
    arv_camera_gv_set_packet_size(camera_, 8192, nullptr);
  } else if (arv_camera_is_gv_device(camera_)) {
    // The largest packet the path carries (jumbo frames where the NIC has them), found by
    // Aravis's test packets; the device's own size when the test fails.
    arv_camera_gv_auto_packet_size(camera_, nullptr);
  }
  Error error;
  stream_ = arv_camera_create_stream(camera_, &AravisCamera::stream_callback, this, error.out());
  if (stream_ == nullptr)
    refuse("stream", "cannot create it (" + error.text() + ")");
  if (ARV_IS_GV_STREAM(stream_)) {
    // A GigE Vision frame arrives as a burst of packets, which overflowed the system's default
    // receive buffer (rmem_default, 208 KiB here) within a 128 KiB Mono16 frame on loopback.
    // Room for several frames (the kernel caps it at net.core.rmem_max).
    const auto bytes = std::clamp<std::size_t>(8 * buffer_bytes_, 1u << 20, 64u << 20);
    g_object_set(stream_, "socket-buffer", ARV_GV_STREAM_SOCKET_BUFFER_FIXED, "socket-buffer-size",
                 static_cast<int>(bytes), nullptr);
  }
  if (loopback && settings_.trigger == TriggerSource::kSoftware)
    warm_up_stream();
  arv_stream_get_statistics(stream_, nullptr, &failures_seen_, &underruns_seen_);
  stream_live_.store(true, std::memory_order_release);
}

void AravisCamera::warm_up_stream() {
  // The GigE Vision stream applies its receive buffer size only once a frame's first packet is
  // in; on loopback the rest of that first frame is already queued, and lost its last packets
  // about one start in three. One frame taken here, before stream_live_, and dropped.
  arv_stream_push_buffer(stream_, arv_buffer_new_allocate(buffer_bytes_));  // the stream's
  Error error;
  arv_camera_start_acquisition(camera_, error.out());
  if (!error)
    arv_camera_software_trigger(camera_, error.out());
  if (!error) {
    // Left in the stream's queue if it does not come: then it is one more buffer of the pool.
    if (ArvBuffer* done = arv_stream_timeout_pop_buffer(stream_, 1'000'000); done != nullptr)
      g_object_unref(done);
  }
  arv_camera_stop_acquisition(camera_, nullptr);
}

bool AravisCamera::is_loopback_gv() const {
  ArvDevice* device = arv_camera_get_device(camera_);
  if (!ARV_IS_GV_DEVICE(device))
    return false;
  GSocketAddress* address = arv_gv_device_get_device_address(ARV_GV_DEVICE(device));
  if (!G_IS_INET_SOCKET_ADDRESS(address))
    return false;
  GInetAddress* ip = g_inet_socket_address_get_address(G_INET_SOCKET_ADDRESS(address));
  return ip != nullptr && g_inet_address_get_is_loopback(ip);
}

void AravisCamera::trigger_thread_main() {
  std::uint64_t pending = 0;
  while (true) {
    const std::uint32_t seen = trigger_signal_.load(std::memory_order_acquire);
    if (!trigger_running_.load(std::memory_order_acquire))
      break;
    double t = 0.0;
    while (requests_->try_pop(t)) {
      if (!trigger_times_->try_push(t))
        rt_message_.store("trigger times not consumed: the stream delivers no frames",
                          std::memory_order_release);
      if (settings_.trigger == TriggerSource::kSoftware)
        ++pending;
    }
    for (; pending > 0; --pending) {
      if (gated_) {
        ArvBuffer* buffer = nullptr;
        if (!idle_buffers_->try_pop(buffer))
          break;  // served when the stream thread gives a buffer back (it signals us)
        arv_stream_push_buffer(stream_, buffer);
      } else {
        Error error;
        arv_camera_software_trigger(camera_, error.out());
        if (error)
          rt_message_.store("TriggerSoftware failed", std::memory_order_release);
      }
    }
    trigger_signal_.wait(seen, std::memory_order_acquire);
  }
}

void AravisCamera::release_stream() noexcept {
  if (stream_ != nullptr) {
    // A callback from here on returns at once; the unref joins Aravis's stream thread (a
    // callback under way finishes with stream_ still valid) and frees the buffers it queues.
    stream_live_.store(false, std::memory_order_release);
    arv_stream_set_emit_signals(stream_, FALSE);
    g_object_unref(stream_);
    stream_ = nullptr;
  }
  ArvBuffer* idle = nullptr;
  while (idle_buffers_ && idle_buffers_->try_pop(idle))
    g_object_unref(idle);
  for (ArvBuffer* buffer : buffers_)
    g_object_unref(buffer);
  buffers_.clear();
}

void AravisCamera::stop() noexcept {
  if (!started_.exchange(false))
    return;
  trigger_running_.store(false, std::memory_order_release);
  trigger_signal_.fetch_add(1, std::memory_order_release);
  trigger_signal_.notify_one();
  if (trigger_thread_.joinable())
    trigger_thread_.join();
  GError* error = nullptr;
  arv_camera_stop_acquisition(camera_, &error);
  if (error != nullptr) {
    rt_message_.store("AcquisitionStop failed", std::memory_order_release);
    g_clear_error(&error);
  }
  release_stream();
}

// ---------------------------------------------------------------------------------------------
// The loop's side

bool AravisCamera::trigger(double loop_time_s) noexcept {
  if (!started_.load(std::memory_order_acquire)) {
    rt_message_.store("trigger() before start()", std::memory_order_release);
    return false;
  }
  if (!requests_->try_push(loop_time_s)) {
    rt_message_.store("trigger() refused: 256 triggers not yet issued", std::memory_order_release);
    return false;
  }
  trigger_signal_.fetch_add(1, std::memory_order_release);
  trigger_signal_.notify_one();  // a futex wake: no lock, never waits
  return true;
}

FrameStatus AravisCamera::poll(Frame& frame) noexcept {
  if (overflow_lost_.load(std::memory_order_acquire) > overflow_reported_) {
    ++overflow_reported_;
    frame.frame_id = overflow_last_id_.load(std::memory_order_acquire);
    lost_frames_.fetch_add(1, std::memory_order_relaxed);
    rt_message_.store("frame lost: the frame ring was full (poll() too slow)",
                      std::memory_order_release);
    return FrameStatus::kLost;
  }
  FrameEvent event;
  if (!events_ || !events_->try_pop(event))
    return FrameStatus::kNone;
  if (event.status == FrameStatus::kOk) {
    Frame& slot = slots_[event.slot];
    frame.counts.swap(slot.counts);  // no copy, no allocation; the slot keeps the old vector
    frame.frame_id = slot.frame_id;
    frame.width_px = slot.width_px;
    frame.height_px = slot.height_px;
    frame.format = slot.format;
    frame.exposure_s = slot.exposure_s;
    frame.trigger_time_s = slot.trigger_time_s;
    frame.device_timestamp_ns = slot.device_timestamp_ns;
    frame.system_timestamp_ns = slot.system_timestamp_ns;
    free_slots_->try_push(event.slot);
    return FrameStatus::kOk;
  }
  frame.frame_id = event.frame_id;
  if (event.status == FrameStatus::kLost)
    lost_frames_.fetch_add(1, std::memory_order_relaxed);
  rt_message_.store(event.reason, std::memory_order_release);
  return event.status;
}

FrameStatus AravisCamera::wait(Frame& frame, double timeout_s) {
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(std::max(0.0, timeout_s));
  while (true) {
    const FrameStatus status = poll(frame);
    if (status != FrameStatus::kNone)
      return status;
    if (std::chrono::steady_clock::now() >= deadline) {
      set_message(name_ + ": no frame within " + std::to_string(timeout_s) + " s");
      return FrameStatus::kTimeout;
    }
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
}

// ---------------------------------------------------------------------------------------------

std::unique_ptr<Camera> make_aravis_camera(const std::string& id) {
  return std::make_unique<AravisCamera>(id);
}

bool aravis_available() noexcept {
  return true;
}

void fake_fill_with(Camera& camera, FakeFill fill) {
  auto* aravis = dynamic_cast<AravisCamera*>(&camera);
  if (aravis == nullptr)
    throw core::InputError(camera.name() + ": a fake fill needs an aravis: camera");
  aravis->set_fake_fill(std::move(fill));
}

}  // namespace piezoshift::camera
