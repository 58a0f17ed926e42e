#pragma once
// The periodic real-time loop: one tick every T = 1 / rate_Hz on absolute deadlines.
//
//   D_0 = start; for k = 0, 1, ...:
//     sleep until D_k (absolute)                        W_k = wake-up
//     stop requested (duration reached, SIGINT/SIGTERM)  -> supervisor.request_stop()
//     clear requested (request_clear())                  -> supervisor.clear_fault(),
//                                                           controller reset (bumpless from 0 V)
//     host mode: apply the host's commands (host_link.hpp)
//     Z_d = profile(k T), or the host's last move plus   (host mode with the servo off: the
//           its running wave generators               host's open-loop volts; the generators
//           (wave_generator.hpp)                      stop when the servo is off or a fault is
//                                                     latched)
//     cycle.step(daq, k, overrun(k-1))                   the one control tick (control_cycle.hpp):
//                                                        read, controller, supervisor, write
//                                                        E_k = end of work
//     stats (period error, wake latency, compute, overrun = E_k - D_k > T), telemetry push,
//     host sample push
//     done when the supervisor has stopped, or has faulted and the outputs are at 0 V
//     D_{k+1} = D_k + T; if E_k > D_{k+1}: skip to the first slot after E_k (counted)
//
// Host mode (LoopConfig::host set, `piezoshift serve`, the guided calibration's LoopRig): the
// loop starts with the servo off and the outputs at 0 V, and takes its set-points (Z_d, actuator
// targets S or open-loop volts) and parameter changes from the host's commands instead of the
// profile.
//
// run() is real-time safe: everything it touches is allocated by the constructor; the telemetry
// and host pushes are lock-free ring writes that drop (and count) on a full ring.
#include <atomic>
#include <cstdint>

#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/runtime/control_cycle.hpp"
#include "piezoshift/runtime/daq_backend.hpp"
#include "piezoshift/runtime/host_link.hpp"
#include "piezoshift/runtime/loop_clock.hpp"
#include "piezoshift/runtime/loop_status.hpp"
#include "piezoshift/runtime/period_stats.hpp"
#include "piezoshift/runtime/safety_supervisor.hpp"
#include "piezoshift/runtime/setpoint_profile.hpp"
#include "piezoshift/runtime/spsc_ring.hpp"
#include "piezoshift/runtime/telemetry.hpp"

namespace piezoshift::runtime {

struct LoopConfig {
  double rate_Hz = 1000.0;  //!< 1 kHz (the paper's T_s = 1 ms) to 10 kHz
  double duration_s = 1.0;  //!< controlled part; the ramp to 0 V follows (infinity: until stopped)
  //! Polled each tick; nonzero stops the run through the safe ramp (set by a signal handler).
  const std::atomic<int>* stop_signal = nullptr;
  //! End the run once a fault has ramped the outputs to 0 V (no operator to clear it).
  bool stop_when_safe_after_fault = true;
  //! Host mode: set-points and servo state from this link (host_link.hpp), samples back to it.
  HostLink* host = nullptr;
  //! When set, the latest tick is published here for a display (loop_status.hpp).
  LoopStatus* status = nullptr;
};

enum class StopReason : std::uint8_t { kDuration, kSignal, kFault };
const char* to_string(StopReason reason) noexcept;

struct LoopResult {
  std::uint64_t ticks = 0;
  StopReason stop_reason = StopReason::kDuration;
  int signal = 0;               //!< the stop_signal value that stopped the run
  FaultRecord fault{};          //!< reason kNone when none was latched (the last one if cleared)
  bool fault_detected = false;  //!< a fault was latched at some point
  double max_output_V = 0.0;
  double min_output_V = 0.0;
  double max_output_slew_V_per_ms = 0.0;  //!< max |ao(k) - ao(k-1)| / T over ticks and channels
  std::uint64_t telemetry_dropped = 0;
  std::uint64_t host_samples_dropped = 0;
  std::uint64_t host_commands_applied = 0;
  Vec3 last_sgs_V{};
  //! The last closed-loop tick of the controlled part, before the ramp to 0 V and before any
  //! fault: Z_d, the actuator targets S, the SGS feedback (tracking error = S - feedback) and,
  //! on the twin, its interferometer at P1..P3 (NaN on hardware). controlled_end_tick: that
  //! tick + 1 (0: there was none).
  std::uint64_t controlled_end_tick = 0;
  Vec3 end_zd_um{};
  Vec3 end_target_um{};
  Vec3 end_feedback_um{};
  Vec3 end_interferometer_um{};
};

class ControlLoop {
 public:
  //! Set-up (allocates). params.sample_time_s is replaced with the loop's real period.
  ControlLoop(const LoopConfig& config, const control::SemiClosedLoopParams& params,
              const SafetyLimits& limits, DaqBackend& daq, LoopClock& clock,
              SetpointProfile profile, SpscRing<TelemetryRecord>* telemetry = nullptr);

  //! Runs until done (see the header comment). The backend must be active. Real-time safe.
  LoopResult run() noexcept;

  //! Any thread: ask the loop to clear a latched fault at its next tick.
  void request_clear() noexcept { clear_requested_.store(true, std::memory_order_release); }

  std::int64_t period_ns() const noexcept { return period_ns_; }
  std::uint64_t duration_ticks() const noexcept { return duration_ticks_; }
  const LoopStats& stats() const noexcept { return stats_; }
  const SafetySupervisor& supervisor() const noexcept { return cycle_.supervisor(); }
  const control::SemiClosedLoopController& controller() const noexcept {
    return cycle_.controller();
  }

 private:
  LoopConfig config_;
  control::SemiClosedLoopParams params_;
  std::int64_t period_ns_;
  std::uint64_t duration_ticks_;
  DaqBackend& daq_;
  LoopClock& clock_;
  SetpointProfile profile_;
  SpscRing<TelemetryRecord>* telemetry_;
  ControlCycle cycle_;
  LoopStats stats_;
  std::atomic<bool> clear_requested_{false};
};

}  // namespace piezoshift::runtime
