#pragma once
// The periodic real-time loop, the one driver of the control tick: `run`, `serve`, `simulate`,
// `calibrate --daq`, the guided calibration's rig and the simulated bench (the calibration
// procedures, the paper's experiments) all step a ControlLoop. One tick every T = 1 / rate_Hz on
// absolute deadlines; run() is start() then tick() until it returns false:
//
//   start():  D_0 = now; supervisor, controller, statistics and result from the start
//   tick():   sleep until D_k (absolute)                 W_k = wake-up
//     stop requested (duration reached, SIGINT/SIGTERM)  -> supervisor.request_stop()
//     clear requested (request_clear())                  -> supervisor.clear_fault(),
//                                                           controller reset (bumpless from 0 V)
//     set-point, by source:
//       profile  Z_d = profile(k T)                         (`run`, `simulate`)
//       host     the host's commands (host_link.hpp): its   (`serve`, the guided rig; with the
//                last move plus its running wave           servo off the host's open-loop
//                generators (wave_generator.hpp)           volts; the generators stop when the
//                                                          servo is off or a fault is latched)
//       owner    whatever drive_*() set between ticks    (the simulated bench)
//     cycle.step(daq, k, overrun(k-1))                   the one control tick (control_cycle.hpp):
//                                                        read, controller, supervisor, write
//                                                        E_k = end of work
//     a newly latched fault is appended to result().faults (fault_list.hpp) and published to
//     the status (loop_status.hpp), with its time and, for `overruns`, the worst lateness
//     E_j - D_{j+1} of the consecutive overruns that tripped it
//     stats (period error, wake latency, compute, overrun = E_k - D_k > T), telemetry push,
//     host sample push
//     done when the supervisor has stopped, or has faulted and the outputs are at 0 V
//     D_{k+1} = D_k + T; if E_k > D_{k+1}: skip to the first slot after E_k (counted)
//
// The timing between the loop and the plant is the DAQ backend's, the same for the board and the
// twin (daq_backend.hpp): what tick k writes acts from tick k+1 on.
//
// Host mode (LoopConfig::host set): the loop starts with the servo off and the outputs at 0 V,
// and takes its set-points (Z_d, actuator targets S or open-loop volts) and parameter changes
// from the host's commands instead of the profile. Owner mode (LoopConfig::owner_drives): the
// same start, and the set-points and parameter changes come from drive_points(),
// drive_actuators(), drive_open_loop() and try_configure(), called by the thread that calls
// tick().
//
// Trigger pulse (owner mode, a backend with a trigger line: daq_backend.hpp): arm_trigger_pulse(N)
// between ticks makes the next tick stage the line high before its read(), so the edge goes out
// in that tick's transaction at its scheduled time; the line is held for N ticks and staged low
// by the tick after them. The edge (tick, scheduled time) is reported by last_trigger_edge(). An
// arm while a pulse is armed or high is refused (false), not queued: the next exposure's trigger
// belongs after the camera's readout anyway, and a refusal keeps every pulse's edge the one its
// arm asked for. Without a pulse armed or high the tick pays a test of two flags.
//
// start(), tick() and run() are real-time safe: everything they touch is allocated by the
// constructor; the telemetry and host pushes are lock-free ring writes that drop (and count) on a
// full ring.
#include <atomic>
#include <cstdint>

#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/runtime/control_cycle.hpp"
#include "piezoshift/runtime/daq_backend.hpp"
#include "piezoshift/runtime/fault_list.hpp"
#include "piezoshift/runtime/host_link.hpp"
#include "piezoshift/runtime/loop_clock.hpp"
#include "piezoshift/runtime/loop_status.hpp"
#include "piezoshift/runtime/period_stats.hpp"
#include "piezoshift/runtime/safety_supervisor.hpp"
#include "piezoshift/runtime/setpoint_profile.hpp"
#include "piezoshift/runtime/spsc_ring.hpp"
#include "piezoshift/runtime/telemetry.hpp"
#include "piezoshift/runtime/wave_generator.hpp"

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
  //! Owner mode (no host): the set-points come from drive_*() between ticks, not from the
  //! profile.
  bool owner_drives = false;
};

enum class StopReason : std::uint8_t { kDuration, kSignal, kFault };
const char* to_string(StopReason reason) noexcept;

struct LoopResult {
  std::uint64_t ticks = 0;
  StopReason stop_reason = StopReason::kDuration;
  int signal = 0;       //!< the stop_signal value that stopped the run
  FaultRecord fault{};  //!< reason kNone when none was latched (the last one if cleared)
  //! Every fault latched, in order (a cleared fault and the next are two entries).
  FaultList faults{};
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

  //! Runs until done: start(), then tick() until it returns false. The backend must be active.
  //! Real-time safe.
  LoopResult run() noexcept;
  //! Starts a run (see the header comment); the clock's present time is D_0. Real-time safe.
  void start() noexcept;
  //! One tick; false when the run is done (result() is then final). Real-time safe.
  bool tick() noexcept;
  //! The run so far (final once tick() returned false).
  const LoopResult& result() const noexcept { return result_; }

  //! Owner mode, between ticks: what the next ticks follow (control_cycle.hpp's): DAQ volts,
  //! the actuator targets S, or Z_d of P1..P3.
  void drive_open_loop(const Vec3& ao_V) noexcept { cycle_.drive_open_loop(ao_V); }
  void drive_actuators(const Vec3& target_um) noexcept { cycle_.drive_actuators(target_um); }
  void drive_points(const Vec3& zd_um) noexcept { cycle_.drive_points(zd_um); }
  //! Owner mode, between ticks: a new controller, or the problem that refused it (nothing
  //! changes then). params.sample_time_s must be the loop's period.
  control::ParamsProblem try_configure(const control::SemiClosedLoopParams& params) noexcept {
    return cycle_.try_configure(params);
  }

  //! Owner mode, between ticks: the controlled part ends at the next tick, as the duration would
  //! end it (the safe ramp to 0 V follows; tick() returns false once it is done).
  void finish() noexcept { finish_requested_ = true; }
  //! Owner mode, between ticks: raise the DAQ's trigger line at the next tick and hold it high for
  //! width_ticks ticks (see the header comment). False, nothing armed: no trigger line, width 0
  //! or above kMaxTriggerPulseTicks, or a pulse already armed or high.
  bool arm_trigger_pulse(std::uint32_t width_ticks = 1) noexcept;
  //! The longest pulse: 1 s at 1 kHz (a camera needs a few us).
  static constexpr std::uint32_t kMaxTriggerPulseTicks = 1000;
  //! Rising edges raised since start(); the last one (valid when trigger_pulses() > 0).
  std::uint64_t trigger_pulses() const noexcept { return trigger_pulses_; }
  const TriggerEdge& last_trigger_edge() const noexcept { return trigger_edge_; }
  //! The level the loop last staged on the trigger line.
  bool trigger_line_high() const noexcept { return trigger_high_; }
  //! The backend, for the owner thread between ticks (its trigger wire: take_trigger_edge()).
  DaqBackend& daq() noexcept { return daq_; }

  //! Any thread: ask the loop to clear a latched fault at its next tick.
  void request_clear() noexcept { clear_requested_.store(true, std::memory_order_release); }

  std::int64_t period_ns() const noexcept { return period_ns_; }
  //! The loop's clock keeps wall time (false: a simulated clock, ticks as fast as they run).
  bool real_time() const noexcept { return clock_.real_time(); }
  std::uint64_t duration_ticks() const noexcept { return duration_ticks_; }
  const LoopStats& stats() const noexcept { return stats_; }
  const SafetySupervisor& supervisor() const noexcept { return cycle_.supervisor(); }
  const control::SemiClosedLoopController& controller() const noexcept {
    return cycle_.controller();
  }
  //! The last tick as a whole: AI, controller, supervisor (ao_V is what went out), statuses.
  const CycleSample& last_cycle() const noexcept { return cycle_.last(); }
  DriveMode mode() const noexcept { return cycle_.mode(); }
  //! Ticks since start().
  std::uint64_t ticks() const noexcept { return tick_; }

 private:
  void check_stop() noexcept;
  void clear_latched_fault() noexcept;
  void apply_host_commands() noexcept;
  void apply(const HostCommand& command) noexcept;
  void choose_setpoint(const CycleTime& t) noexcept;
  void drive_trigger_line(const CycleTime& t) noexcept;
  void record_outputs(const CycleSample& cs, const Vec3& zd) noexcept;
  void record_fault() noexcept;
  void publish_status(const CycleSample& cs, const Vec3& zd, const CycleTime& t) noexcept;
  void push_telemetry(const CycleSample& cs, const Vec3& zd, const CycleTime& t,
                      std::int64_t wake_ns, std::int64_t end_ns) noexcept;
  void push_host_sample(const CycleSample& cs, const Vec3& zd, const CycleTime& t,
                        std::int64_t wake_ns) noexcept;
  bool done(const CycleSample& cs) noexcept;
  void next_deadline(std::int64_t end_ns) noexcept;

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

  // The run in progress (start()).
  LoopResult result_{};
  std::uint64_t tick_ = 0;
  std::int64_t start_ns_ = 0;
  std::int64_t deadline_ns_ = 0;
  std::int64_t previous_deadline_ns_ = 0;
  std::int64_t previous_wake_ns_ = 0;
  bool previous_overran_ = false;
  std::int64_t overrun_worst_late_ns_ = 0;  // over the present run of consecutive overruns
  bool was_faulted_ = false;                // the supervisor's latch at the previous tick
  std::uint64_t recorded_fault_tick_ = 0;   // the tick of the last fault recorded
  bool stop_requested_ = false;
  bool finish_requested_ = false;
  bool done_ = false;
  Vec3 previous_ao_V_{};
  // Host mode: the host's Z_d, its wave generators (fixed-size; the tables are the host's),
  // the last command applied and the last parameter change's outcome.
  Vec3 host_zd_um_{};
  WaveGenerator wave_;
  std::uint64_t applied_sequence_ = 0;
  control::ParamsProblem configure_problem_ = control::ParamsProblem::kNone;
  // Owner mode: the trigger pulse (armed for the next tick; ticks still high after this one).
  bool trigger_armed_ = false;
  bool trigger_high_ = false;
  std::uint32_t trigger_width_ticks_ = 1;
  std::uint32_t trigger_ticks_left_ = 0;
  std::uint64_t trigger_pulses_ = 0;
  TriggerEdge trigger_edge_{};
};

}  // namespace piezoshift::runtime
