#pragma once
// The loop's time source, injectable so that tests and benches are deterministic:
//   MonotonicClock   CLOCK_MONOTONIC, clock_nanosleep(TIMER_ABSTIME): absolute deadlines, so the
//                    schedule never drifts with the loop's own run time
//   SimulatedClock   "as fast as possible": sleep_until() jumps to the deadline, no sleeping; time
//                    moves only by deadlines and by stall() (the overrun fault injection)
// All members are real-time safe (no heap, no locks, no I/O).
#include <cstdint>

namespace piezoshift::runtime {

class LoopClock {
 public:
  virtual ~LoopClock() = default;
  //! Nanoseconds on a monotonic time line.
  virtual std::int64_t now_ns() noexcept = 0;
  //! Returns at or after the absolute time deadline_ns (immediately if it has passed).
  virtual void sleep_until_ns(std::int64_t deadline_ns) noexcept = 0;
  //! Spends duration_ns of loop time (fault injection: an overrun burst).
  virtual void stall_ns(std::int64_t duration_ns) noexcept = 0;
  //! True when time is the wall clock (the loop then asks for real-time scheduling).
  virtual bool real_time() const noexcept = 0;
};

//! CLOCK_MONOTONIC with absolute-deadline sleeps. sleep_until_ns() resumes after EINTR.
class MonotonicClock final : public LoopClock {
 public:
  std::int64_t now_ns() noexcept override;
  void sleep_until_ns(std::int64_t deadline_ns) noexcept override;
  void stall_ns(std::int64_t duration_ns) noexcept override;  // busy-waits
  bool real_time() const noexcept override { return true; }
};

//! Free-running time for tests and benches: deterministic, as fast as the CPU allows.
class SimulatedClock final : public LoopClock {
 public:
  explicit SimulatedClock(std::int64_t start_ns = 0) noexcept : now_(start_ns) {}
  std::int64_t now_ns() noexcept override { return now_; }
  void sleep_until_ns(std::int64_t deadline_ns) noexcept override {
    if (deadline_ns > now_)
      now_ = deadline_ns;
  }
  void stall_ns(std::int64_t duration_ns) noexcept override {
    if (duration_ns > 0)
      now_ += duration_ns;
  }
  bool real_time() const noexcept override { return false; }

 private:
  std::int64_t now_;
};

}  // namespace piezoshift::runtime
