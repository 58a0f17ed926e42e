#pragma once
// A free-running loop time (as SimulatedClock: sleep_until() jumps to the deadline, no sleeping)
// that another thread paces: sleep_until_ns() waits until that thread has allowed time up to the
// deadline (allow_until_ns()). A procedure that drives the real-time loop through its host link
// (rig/loop_rig.hpp) on the twin runs as fast as the CPU allows and still knows at which
// tick each of its commands is applied: the loop is held before the next tick while the
// procedure pushes them. Deterministic, for tests and `calibrate --daq sim-rt --free-run`.
//
// now_ns() and sleep_until_ns() are the loop thread's; allow_until_ns() and open() any thread's.
// Waiting is std::atomic::wait (a futex on Linux): no locks, no heap.
#include <atomic>
#include <cstdint>
#include <limits>

#include "piezoshift/runtime/loop_clock.hpp"

namespace piezoshift::runtime {

class PacedClock final : public LoopClock {
 public:
  std::int64_t now_ns() noexcept override { return now_.load(std::memory_order_relaxed); }
  void sleep_until_ns(std::int64_t deadline_ns) noexcept override {
    for (std::int64_t allowed = allowed_.load(std::memory_order_acquire); deadline_ns > allowed;
         allowed = allowed_.load(std::memory_order_acquire))
      allowed_.wait(allowed, std::memory_order_acquire);
    if (deadline_ns > now_ns())
      now_.store(deadline_ns, std::memory_order_relaxed);
  }
  void stall_ns(std::int64_t duration_ns) noexcept override {
    if (duration_ns > 0)
      now_.fetch_add(duration_ns, std::memory_order_relaxed);
  }
  bool real_time() const noexcept override { return false; }

  //! Lets the loop run up to the deadline t_ns (never backwards).
  void allow_until_ns(std::int64_t t_ns) noexcept {
    std::int64_t a = allowed_.load(std::memory_order_relaxed);
    while (t_ns > a && !allowed_.compare_exchange_weak(a, t_ns, std::memory_order_release)) {
    }
    allowed_.notify_all();
  }
  //! No more pacing: the loop runs free (to finish its ramp to 0 V when stopped).
  void open() noexcept { allow_until_ns(std::numeric_limits<std::int64_t>::max()); }

 private:
  std::atomic<std::int64_t> now_{0};
  std::atomic<std::int64_t> allowed_{-1};  // the first tick (deadline 0) waits too
};

}  // namespace piezoshift::runtime
