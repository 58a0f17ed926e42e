#pragma once
// Elapsed wall time on the steady clock (no clock change moves it): what a run reports as its
// wall_time_s, and the deadlines of waits off the loop. The loop's own time is the loop clock's
// (runtime/loop_clock.hpp), never this.
#include <chrono>

namespace piezoshift::core {

//! Seconds of steady-clock time since t0.
inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace piezoshift::core
