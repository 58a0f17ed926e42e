// aravis:ID's side on Aravis's stream thread (its BUFFER_DONE callback checks each buffer, counts
// the frames lost, unpacks the pixels into a free slot and publishes the event) and the fill of
// Aravis's fake camera. The threads and their rings: aravis_camera.cpp.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>

#include "aravis_camera_impl.hpp"

namespace piezoshift::camera {
namespace {

using aravis_detail::arv_format;
using aravis_detail::bytes_per_pixel;
using aravis_detail::FrameEvent;

std::int64_t monotonic_ns() noexcept {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

const char* buffer_status_text(ArvBufferStatus status) noexcept {
  switch (status) {
    case ARV_BUFFER_STATUS_SUCCESS:
      return "frame complete";
    case ARV_BUFFER_STATUS_CLEARED:
      return "frame lost: buffer status CLEARED";
    case ARV_BUFFER_STATUS_TIMEOUT:
      return "frame lost: buffer status TIMEOUT (not all packets arrived in time)";
    case ARV_BUFFER_STATUS_MISSING_PACKETS:
      return "frame lost: buffer status MISSING_PACKETS";
    case ARV_BUFFER_STATUS_WRONG_PACKET_ID:
      return "frame lost: buffer status WRONG_PACKET_ID";
    case ARV_BUFFER_STATUS_SIZE_MISMATCH:
      return "frame lost: buffer status SIZE_MISMATCH (image larger than the buffer)";
    case ARV_BUFFER_STATUS_FILLING:
      return "frame lost: buffer status FILLING";
    case ARV_BUFFER_STATUS_ABORTED:
      return "frame lost: buffer status ABORTED";
    default:
      return "frame lost: buffer status not SUCCESS";
  }
}

// GigE Vision 1.x block ids are 16 bits and skip 0 when they wrap (65535 -> 1); Aravis's fake
// camera starts at 65400 to exercise exactly that.
constexpr std::uint64_t kGvBlockIdMax = 0xFFFF;

}  // namespace

// ---------------------------------------------------------------------------------------------
// Aravis's stream thread

void AravisCamera::stream_callback(void* user, ArvStreamCallbackType type, ArvBuffer* /*buffer*/) {
  auto* self = static_cast<AravisCamera*>(user);
  if (type == ARV_STREAM_CALLBACK_TYPE_BUFFER_DONE &&
      self->stream_live_.load(std::memory_order_acquire))
    self->on_buffer_done();
}

void AravisCamera::on_buffer_done() noexcept {
  // The stream pushed the finished buffer onto its output queue just before calling back: take
  // one per call, so every buffer is checked once and goes back to the pool.
  ArvBuffer* buffer = arv_stream_try_pop_buffer(stream_);
  if (buffer == nullptr)
    return;
  check_buffer(buffer);
  recycle(buffer);
}

void AravisCamera::recycle(ArvBuffer* buffer) noexcept {
  if (gated_) {
    idle_buffers_->try_push(buffer);
    trigger_signal_.fetch_add(1, std::memory_order_release);
    trigger_signal_.notify_one();
  } else {
    arv_stream_push_buffer(stream_, buffer);
  }
}

std::uint64_t AravisCamera::missing_before(std::uint64_t device_id, bool trusted) noexcept {
  // A failed buffer can carry the id of the frame it held before: Aravis sets the id from the
  // leader, which may be the packet that was lost (seen with arv-fake-gv-camera-0.8 -r). It
  // counts as the next frame; the next good frame's id tells what else is missing. The pool's
  // buffers are new at start(), so before the first frame a failed buffer's id is either its
  // own or 0 (unknown: the loss is reported with id 0).
  if (!trusted && (have_last_id_ || device_id == 0)) {
    if (have_last_id_) {
      last_device_id_ = last_device_id_ == kGvBlockIdMax ? 1 : last_device_id_ + 1;
      ++last_frame_id_;
    }
    return 0;
  }
  if (!have_last_id_) {
    have_last_id_ = true;
    last_device_id_ = device_id;
    last_frame_id_ = device_id;
    return 0;
  }
  std::uint64_t advance = 0;
  if (device_id > last_device_id_) {
    advance = device_id - last_device_id_;
  } else if (last_device_id_ <= kGvBlockIdMax && device_id >= 1 &&
             kGvBlockIdMax - last_device_id_ + device_id < kGvBlockIdMax / 2) {
    advance = (kGvBlockIdMax - last_device_id_) + device_id;  // wrapped, skipping 0
  }
  // Otherwise the device counts from the start again: nothing known to be missing.
  last_device_id_ = device_id;
  last_frame_id_ += std::max<std::uint64_t>(advance, 1);
  return advance > 1 ? advance - 1 : 0;
}

void AravisCamera::check_buffer(ArvBuffer* buffer) noexcept {
  const ArvBufferStatus status = arv_buffer_get_status(buffer);
  const std::uint64_t previous_frame_id = last_frame_id_;
  const std::uint64_t missing =
      missing_before(arv_buffer_get_frame_id(buffer), status == ARV_BUFFER_STATUS_SUCCESS);
  // A gap may already have been reported from the stream's counters (below): not twice.
  const std::uint64_t credited = std::min(missing, counter_only_lost_);
  counter_only_lost_ -= credited;
  for (std::uint64_t i = credited; i < missing; ++i)
    publish_lost(previous_frame_id + 1 + i, "frame lost: a gap in the device's frame ids");
  for (std::uint64_t i = 0; i < missing; ++i)
    next_trigger_time();  // the lost frames' triggers
  // The stream's own counters: a buffer the stream failed, or a frame it had no buffer for. Ids
  // explain most of them; what they do not explain is a loss all the same. The gated fake
  // camera underruns by design (no buffer queued until a trigger).
  guint64 failures = 0, underruns = 0;
  arv_stream_get_statistics(stream_, nullptr, &failures, &underruns);
  std::uint64_t counted = failures - failures_seen_;
  if (!gated_)
    counted += underruns - underruns_seen_;
  failures_seen_ = failures;
  underruns_seen_ = underruns;
  const std::uint64_t explained = missing + (status != ARV_BUFFER_STATUS_SUCCESS ? 1 : 0);
  for (std::uint64_t i = explained; i < counted; ++i) {
    publish_lost(last_frame_id_, "frame lost: counted by the stream (n_failures/n_underruns)");
    ++counter_only_lost_;
  }
  if (const char* fill_error = fill_error_.exchange(nullptr); fill_error != nullptr) {
    next_trigger_time();
    publish({FrameStatus::kError, 0, last_frame_id_, fill_error});
  } else if (status != ARV_BUFFER_STATUS_SUCCESS) {
    next_trigger_time();
    publish_lost(last_frame_id_, buffer_status_text(status));
  } else {
    publish_frame(buffer, last_frame_id_);
  }
}

double AravisCamera::next_trigger_time() noexcept {
  double t = std::numeric_limits<double>::quiet_NaN();
  trigger_times_->try_pop(t);
  return t;
}

void AravisCamera::publish(const FrameEvent& event) noexcept {
  if (events_->try_push(event))
    return;
  if (event.status == FrameStatus::kOk)
    spare_slot_ = event.slot;  // never reached poll(): reuse it for the next frame
  overflow_last_id_.store(event.frame_id, std::memory_order_release);
  overflow_lost_.fetch_add(1, std::memory_order_acq_rel);
}

void AravisCamera::publish_lost(std::uint64_t frame_id, const char* reason) noexcept {
  publish({FrameStatus::kLost, 0, frame_id, reason});
}

void AravisCamera::publish_frame(ArvBuffer* buffer, std::uint64_t frame_id) noexcept {
  const double trigger_time_s = next_trigger_time();
  const int width = arv_buffer_get_image_width(buffer);
  const int height = arv_buffer_get_image_height(buffer);
  if (arv_buffer_get_payload_type(buffer) != ARV_BUFFER_PAYLOAD_TYPE_IMAGE ||
      arv_buffer_get_image_pixel_format(buffer) != arv_format(settings_.format) ||
      width != settings_.width_px || height != settings_.height_px) {
    publish({FrameStatus::kError, 0, frame_id,
             "frame is not the configured image (payload type, PixelFormat or size differ)"});
    return;
  }
  std::size_t size = 0;
  const auto* data = static_cast<const std::uint8_t*>(arv_buffer_get_image_data(buffer, &size));
  // The fake camera leaves the size at 0 when a fill-pattern callback other than its own wrote
  // the image (only its own sets the private received size); the buffer is ours and full.
  if (size == 0 && fake_fill_)
    size = buffer_bytes_;
  if (data == nullptr || size < image_bytes_) {
    publish({FrameStatus::kError, 0, frame_id, "frame shorter than the configured image"});
    return;
  }
  std::uint32_t slot = 0;
  if (spare_slot_ >= 0) {
    slot = static_cast<std::uint32_t>(spare_slot_);
    spare_slot_ = -1;
  } else if (!free_slots_->try_pop(slot)) {
    publish_lost(frame_id, "frame lost: every frame slot is waiting for poll() (ring full)");
    return;
  }
  Frame& out = slots_[slot];
  const std::size_t n = static_cast<std::size_t>(width) * height;
  out.counts.resize(n);  // allocates only if poll() handed back a vector of another size
  if (settings_.format == PixelFormat::kMono8) {
    std::copy(data, data + n, out.counts.begin());
  } else {  // Mono12 (unpacked) and Mono16: 16-bit little endian
    for (std::size_t i = 0; i < n; ++i)
      out.counts[i] = static_cast<std::uint16_t>(data[2 * i] | (data[2 * i + 1] << 8));
  }
  out.frame_id = frame_id;
  out.width_px = width;
  out.height_px = height;
  out.format = settings_.format;
  out.exposure_s = settings_.exposure_s;
  out.trigger_time_s = trigger_time_s;
  out.device_timestamp_ns = static_cast<std::int64_t>(arv_buffer_get_timestamp(buffer));
  out.system_timestamp_ns = monotonic_ns();
  publish({FrameStatus::kOk, slot, frame_id, nullptr});
}

// ---------------------------------------------------------------------------------------------
// The fake camera's fill pattern

void AravisCamera::fake_fill_callback(ArvBuffer* buffer, void* user, guint32 exposure_us,
                                      guint32 /*gain*/, ArvPixelFormat format) {
  static_cast<AravisCamera*>(user)->fill_fake_buffer(buffer, exposure_us, format);
}

void AravisCamera::fill_fake_buffer(ArvBuffer* buffer, guint32 exposure_us,
                                    ArvPixelFormat arv_pixel_format) noexcept {
  FakeFillFrame frame;
  frame.index = fill_index_++;
  frame.device_frame_id = arv_buffer_get_frame_id(buffer);
  frame.width_px = arv_buffer_get_image_width(buffer);
  frame.height_px = arv_buffer_get_image_height(buffer);
  frame.exposure_s = exposure_us * 1e-6;
  if (arv_pixel_format == ARV_PIXEL_FORMAT_MONO_8)
    frame.format = PixelFormat::kMono8;
  else if (arv_pixel_format == ARV_PIXEL_FORMAT_MONO_12)
    frame.format = PixelFormat::kMono12;
  else if (arv_pixel_format == ARV_PIXEL_FORMAT_MONO_16)
    frame.format = PixelFormat::kMono16;
  else {
    fill_error_.store("fake fill: the fake camera is not in Mono8, Mono12 or Mono16");
    return;
  }
  const std::size_t n = static_cast<std::size_t>(frame.width_px) * frame.height_px;
  if (n * bytes_per_pixel(frame.format) > buffer_bytes_) {
    fill_error_.store("fake fill: the image is larger than the buffer");
    return;
  }
  try {
    fill_counts_.assign(n, 0);
    fake_fill_(frame, std::span<std::uint16_t>(fill_counts_));
  } catch (...) {
    fill_error_.store("fake fill: the fill function threw");
    return;
  }
  // The buffer is one of ours (arv_buffer_new_allocate), writable; Aravis only hands it out const.
  auto* data = static_cast<std::uint8_t*>(const_cast<void*>(arv_buffer_get_data(buffer, nullptr)));
  const std::uint16_t max_count = static_cast<std::uint16_t>((1u << bit_depth(frame.format)) - 1u);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint16_t v = std::min(fill_counts_[i], max_count);  // saturates as a sensor does
    if (frame.format == PixelFormat::kMono8) {
      data[i] = static_cast<std::uint8_t>(v);
    } else {
      data[2 * i] = static_cast<std::uint8_t>(v & 0xFF);
      data[2 * i + 1] = static_cast<std::uint8_t>(v >> 8);
    }
  }
}
}  // namespace piezoshift::camera
