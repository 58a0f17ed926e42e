#pragma once
// OVF? as PI defines it: "Overflow means that the control variables are out of range (can only
// happen if controller is in closed-loop mode)" (PI's PIPython, qOVF; docs/gcs.md). A PID resting
// at an output limit while its axis is on target is not that: at the bottom of the travel the
// loop holds the stage at 0 V, its lower limit, and the stage is where it was asked to be. So an
// axis overflows when, with the loop closed, a channel's PID has sat at its output limit
// (the samples' saturated_mask) while the axis was off target (|POS? - MOV?| beyond the ONT?
// tolerance, or not finite) for the whole settle window without a break: the loop is pushing
// against a limit and cannot hold the target. A step that touches a rail for less than the window
// while it moves is not an overflow.
// Not thread-safe: the server's one network thread owns it.
#include <array>
#include <cstddef>
#include <cstdint>

namespace piezoshift::host {

class OverflowMonitor {
 public:
  //! window_samples: the settle window in loop samples (>= 1).
  explicit OverflowMonitor(std::uint64_t window_samples) noexcept
      : window_(window_samples < 1 ? 1 : window_samples) {}

  //! One loop sample. off_target[a]: axis a is not within its on-target tolerance of its target.
  void update(bool closed_loop, std::uint8_t saturated_mask,
              const std::array<bool, 3>& off_target) noexcept {
    const bool pinned = closed_loop && saturated_mask != 0;
    for (std::size_t a = 0; a < pinned_.size(); ++a)
      pinned_[a] = pinned && off_target[a] ? pinned_[a] + 1 : 0;
  }
  //! OVF? of axis a (0 Z, 1 U, 2 V).
  bool overflow(std::size_t a) const noexcept { return pinned_[a] >= window_; }

 private:
  std::uint64_t window_;
  std::array<std::uint64_t, 3> pinned_{};
};

}  // namespace piezoshift::host
