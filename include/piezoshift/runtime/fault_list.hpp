#pragma once
// Every fault the supervisor latched in a run, not only the first: `serve` clears faults (a
// client's SVO) and runs on, so one run can latch many. The loop appends an entry in the tick a
// latch appears (a new latch, or one after a clear), in a fixed array: no heap in the loop.
// Beyond kMaxFaultsKept the count goes on and the entries stop (the first ones say what went
// wrong; a summary says how many more there were).
//
// LatchedFault adds to the supervisor's FaultRecord what a reader needs to name it: the tick's
// scheduled time, and for `overruns` the worst lateness of the consecutive overruns that tripped
// it (the end of a tick's work after the next tick's deadline).
#include <array>
#include <cstdint>

#include "piezoshift/runtime/safety_supervisor.hpp"

namespace piezoshift::runtime {

struct LatchedFault {
  FaultRecord fault{};
  double t_s = 0.0;               //!< the tick's scheduled time since the loop started
  double worst_lateness_s = 0.0;  //!< `overruns`: the worst tick's end after the next deadline
};

inline constexpr std::uint32_t kMaxFaultsKept = 16;

struct FaultList {
  std::array<LatchedFault, kMaxFaultsKept> entries{};
  std::uint32_t count = 0;  //!< faults latched (entries holds the first kMaxFaultsKept)

  std::uint32_t kept() const noexcept { return count < kMaxFaultsKept ? count : kMaxFaultsKept; }
  //! Real-time safe: keeps the entry while there is room, counts it always.
  void append(const LatchedFault& f) noexcept {
    if (count < kMaxFaultsKept)
      entries[count] = f;
    ++count;
  }
};

//! The unit of a rule's value and limit ("V", "um", "ticks", "reversals"; "" for a DAQ status
//! code).
const char* value_unit(FaultReason reason) noexcept;

}  // namespace piezoshift::runtime
