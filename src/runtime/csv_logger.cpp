#include "piezoshift/runtime/csv_logger.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <iterator>

#include <fmt/format.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/runtime/safety_supervisor.hpp"

namespace piezoshift::runtime {

namespace {
constexpr std::size_t kFlushBytes = std::size_t{1} << 20;
}

std::string CsvLogger::header(bool with_truth) {
  std::string h =
      "tick,t_s,zd1_um,zd2_um,zd3_um,s1_um,s2_um,s3_um,sgs1_V,sgs2_V,sgs3_V,"
      "request1_V,request2_V,request3_V,ao1_V,ao2_V,ao3_V,";
  if (with_truth) {
    h += "truth1_um,truth2_um,truth3_um,interferometer1_um,interferometer2_um,"
         "interferometer3_um,";
  }
  h += "wake_latency_us,compute_us,overrun,limited,held,state,fault_reason,fault_channel,"
       "read_status,write_status";
  return h;
}

void CsvLogger::format(const TelemetryRecord& r, bool with_truth, std::string& out) {
  auto it = std::back_inserter(out);
  const auto v3 = [&it](const Vec3& v) {
    fmt::format_to(it, "{:.9g},{:.9g},{:.9g},", v[0], v[1], v[2]);
  };
  fmt::format_to(it, "{},{:.7f},", r.tick, r.t_s);
  v3(r.zd_um);
  v3(r.target_um);
  v3(r.sgs_V);
  v3(r.request_V);
  v3(r.ao_V);
  if (with_truth) {
    v3(r.truth_um);
    v3(r.interferometer_um);
  }
  fmt::format_to(it, "{:.3f},{:.3f},{},{},{},{},{},{},{},{}\n", r.wake_latency_us, r.compute_us,
                 r.overrun, r.limited, r.held, r.state, r.fault_reason, r.fault_channel,
                 r.read_status, r.write_status);
}

CsvLogger::CsvLogger(CsvLoggerOptions options)
    : options_(std::move(options)), ring_(options_.ring_capacity) {
  fd_ = ::open(options_.path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    throw core::InputError(
        fmt::format("{}: cannot create the log file: {}", options_.path, std::strerror(errno)));
  }
  buffer_ = header(options_.with_truth) + "\n";
  buffer_.reserve(2 * kFlushBytes);
  if (!flush_buffer()) {
    ::close(fd_);
    fd_ = -1;
    throw core::InputError(fmt::format("{}: cannot write the log file: {}", options_.path, error_));
  }
}

CsvLogger::~CsvLogger() {
  stop();
}

void CsvLogger::start() {
  if (started_)
    return;
  started_ = true;
  thread_ = std::thread([this] { run(); });
}

void CsvLogger::stop() {
  if (stopped_)
    return;
  stopped_ = true;
  stop_.store(true, std::memory_order_release);
  if (thread_.joinable()) {
    thread_.join();
  } else {
    std::uint8_t last = 0;
    drain_into_buffer(last);  // never started: write what was pushed
    flush_buffer();
  }
  if (fd_ >= 0) {
    if (error_.empty() && ::fdatasync(fd_) != 0)
      error_ = fmt::format("fdatasync: {}", std::strerror(errno));
    ::close(fd_);
    fd_ = -1;
  }
}

std::string CsvLogger::error() const {
  return error_;
}

void CsvLogger::drain_into_buffer(std::uint8_t& last_reason) {
  TelemetryRecord r;
  while (ring_.try_pop(r)) {
    if (r.fault_reason != last_reason) {
      if (r.fault_reason != 0 && options_.events != nullptr) {
        fmt::print(options_.events,
                   "piezoshift: fault latched at tick {} (t = {:.4f} s): {}{}; outputs ramping "
                   "to 0 V\n",
                   r.tick, r.t_s, to_string(static_cast<FaultReason>(r.fault_reason)),
                   r.fault_channel >= 0 ? fmt::format(" on channel {}", r.fault_channel + 1)
                                        : std::string());
        std::fflush(options_.events);
      }
      last_reason = r.fault_reason;
    }
    if (error_.empty()) {
      format(r, options_.with_truth, buffer_);
      written_.fetch_add(1, std::memory_order_relaxed);
      if (buffer_.size() >= kFlushBytes)
        flush_buffer();
    }
  }
}

bool CsvLogger::flush_buffer() {
  if (!error_.empty()) {
    buffer_.clear();
    return false;
  }
  const char* p = buffer_.data();
  std::size_t left = buffer_.size();
  while (left > 0) {
    const ssize_t n = ::write(fd_, p, left);
    if (n < 0) {
      if (errno == EINTR)
        continue;
      error_ = fmt::format("write: {}", std::strerror(errno));
      buffer_.clear();
      return false;
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  buffer_.clear();
  return true;
}

void CsvLogger::run() {
  using Clock = std::chrono::steady_clock;
  const auto flush_every = std::chrono::duration<double>(options_.flush_interval_s);
  const auto sync_every = std::chrono::duration<double>(options_.sync_interval_s);
  auto last_flush = Clock::now();
  auto last_sync = last_flush;
  std::uint8_t last_reason = 0;
  bool dirty = false;
  for (;;) {
    const bool stopping = stop_.load(std::memory_order_acquire);
    const std::size_t before = buffer_.size();
    drain_into_buffer(last_reason);
    const bool got = buffer_.size() != before;
    const auto now = Clock::now();
    if (!buffer_.empty() && now - last_flush >= flush_every) {
      dirty = flush_buffer() || dirty;
      last_flush = now;
    }
    if (dirty && error_.empty() && now - last_sync >= sync_every) {
      if (::fdatasync(fd_) != 0)
        error_ = fmt::format("fdatasync: {}", std::strerror(errno));
      dirty = false;
      last_sync = now;
    }
    if (stopping) {
      drain_into_buffer(last_reason);  // what was pushed before stop() was called
      flush_buffer();
      return;
    }
    if (!got)
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

}  // namespace piezoshift::runtime
