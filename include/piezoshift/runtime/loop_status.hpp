#pragma once
// The loop's latest tick for a display (`run`'s live status line on a terminal): relaxed atomic
// stores by the real-time loop every tick, loads by any other thread at its own pace. Fields may
// come from neighbouring ticks (no seqlock): good enough for a human reading a few lines a
// second, not for data (use the telemetry ring, telemetry.hpp). Lock-free, no heap.
//
// The faults latched (fault_list.hpp) are exact: the loop writes entry i once, then stores
// faults_published = i + 1 (release); a reader that loads the count (acquire) may read every entry
// below it. `run` and `serve` print each fault from there as it latches (fault_report.hpp).
#include <array>
#include <atomic>
#include <cstdint>

#include "piezoshift/control/vec3.hpp"
#include "piezoshift/runtime/fault_list.hpp"

namespace piezoshift::runtime {

struct LoopStatus {
  std::atomic<std::uint64_t> ticks{0};  //!< ticks done
  std::atomic<double> t_s{0.0};
  std::array<std::atomic<double>, 3> zd_um{};        //!< Z_d in force
  std::array<std::atomic<double>, 3> target_um{};    //!< S
  std::array<std::atomic<double>, 3> feedback_um{};  //!< SGS
  std::atomic<std::uint8_t> state{0};                //!< SupervisorState as a number
  std::atomic<std::uint8_t> fault_reason{0};         //!< FaultReason as a number
  //! Faults latched since the loop started; entries below min(it, kMaxFaultsKept) are final.
  std::atomic<std::uint32_t> faults_published{0};
  std::array<LatchedFault, kMaxFaultsKept> faults{};

  void publish_vec(std::array<std::atomic<double>, 3>& to, const control::Vec3& v) noexcept {
    for (std::size_t i = 0; i < 3; ++i)
      to[i].store(v[i], std::memory_order_relaxed);
  }
  static control::Vec3 load_vec(const std::array<std::atomic<double>, 3>& from) noexcept {
    return control::Vec3{from[0].load(std::memory_order_relaxed),
                         from[1].load(std::memory_order_relaxed),
                         from[2].load(std::memory_order_relaxed)};
  }
};

}  // namespace piezoshift::runtime
