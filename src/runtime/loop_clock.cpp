#include "piezoshift/runtime/loop_clock.hpp"

#include <time.h>

#include <cerrno>

namespace piezoshift::runtime {

namespace {
constexpr std::int64_t kNsPerS = 1'000'000'000;
}

std::int64_t MonotonicClock::now_ns() noexcept {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * kNsPerS + ts.tv_nsec;
}

void MonotonicClock::sleep_until_ns(std::int64_t deadline_ns) noexcept {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(deadline_ns / kNsPerS);
  ts.tv_nsec = static_cast<long>(deadline_ns % kNsPerS);
  // Absolute deadline: resuming after a signal sleeps to the same instant, never longer.
  while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

void MonotonicClock::stall_ns(std::int64_t duration_ns) noexcept {
  const std::int64_t until = now_ns() + duration_ns;
  while (now_ns() < until) {
  }
}

}  // namespace piezoshift::runtime
