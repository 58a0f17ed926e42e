#pragma once
// The safety supervisor: always between the controller and the DAQ. Every tick it checks the
// inputs, latches the first fault, and shapes the outputs. Per tick, with T the tick's period:
//
//   rules (while running or stopping; the first that trips is latched with reason, tick, channel):
//     read status != ok                                   -> daq-read
//     previous write status is an error                   -> daq-write
//     consecutive overrun ticks >= max_consecutive_overruns -> overruns (unless
//                                                            trip_on_overruns is never)
//     per channel i, v = sgs_V[i]:
//       v is NaN or infinite                              -> sgs-not-finite
//       |v| >= adc_full_scale_V - rail_margin_V           -> sgs-rail   (ADC clipped: "stuck at a
//                                                                        rail"; the stage cannot
//                                                                        get there, see below)
//       v < sgs_min_V or v > sgs_max_V                    -> sgs-range  (outside the conditioner)
//       |v - v_prev| > sgs_noise_V + jump_factor * max_slew_V_per_s * T * g_i
//                                                         -> sgs-jump   (faster than the stage can
//                                                                        follow its slew-limited
//                                                                        drive)
//     only while running (not while ramping down on a stop):
//       closed loop only (in.closed_loop; open loop has no target to track and may sit at 10 V):
//       |target_um - feedback_um| > tracking_error_um for tracking_time_s      -> tracking
//       feedback_um outside [g_min u_um - b, g_max u_um + b] for response_time_s -> response
//         (u_um: the output applied in the previous tick, in um of command; b response_band_um.
//          The stack must answer its drive: a dead amplifier, a split stack or a frozen sensor
//          leave the SGS where it was while the drive moves.)
//       closed loop only:
//       output at output_max_V for saturation_time_s                           -> saturation
//         (the loop has lost authority: the target is out of reach)
//       closed loop only:
//       oscillation_reversals reversals of the tracking error S - y within oscillation_time_s,
//       each a swing of at least oscillation_band_um, with S steady between them (it moved less
//       than the band since the previous reversal)                             -> oscillation
//         (an unstable loop: the slew limit holds it in a limit cycle that stays inside the
//          tracking band on average, so `tracking` never sees it)
//   outputs:
//     desired   = running ? controller request : 0 V         (fault or stop: ramp to 0)
//     clamped   = clamp(desired, output_min_V, output_max_V)
//     step      = running ? max_slew_V_per_s T : safe_ramp_V_per_s T
//     ao        = ao_prev + clamp(clamped - ao_prev, -step, +step)
//     hold integrators = not running, or a limit acted this tick (conditional integration, so an
//                        incremental PID does not wind up against the slew limit)
//   states: running -> (fault) faulted, latched until clear_fault()
//           running -> (request_stop) stopping -> (outputs all 0) stopped
//
// g_i = G / (drive_V_per_um sgs_um_per_V) is the SGS volts per DAQ volt with G = stage_gain, the
// stack's share of its free stroke against the mechanism (Eq. 1: 0.912), an upper bound for a real
// stage; so the jump bound is the SGS change a slew-limited drive can cause in one tick, times
// jump_factor >= 2 (a lightly damped second-order stage overshoots a ramp's rate at most twice).
// A loop that oscillates pumps the mechanism's resonance past that bound and trips it too.
//
// update() is real-time safe: no heap, no exceptions, no I/O. configure() is set-up.
#include <array>
#include <cstdint>

#include "piezoshift/control/signal_scaling.hpp"
#include "piezoshift/control/vec3.hpp"
#include "piezoshift/runtime/daq_backend.hpp"

namespace piezoshift::runtime {

struct SafetyLimits {
  // Outputs, in DAQ volts; the x15 amplifier makes 0..10 V into 0..150 V at the stack (Section 4).
  double output_min_V = 0.0;   //!< 0 V at the stack: the amplifier's and stack's lower limit
  double output_max_V = 10.0;  //!< 150 V at the stack (Section 4: 0-10 V in, 0-150 V out)
  //! 7 W average amplifier power (Section 4) at 150 V is 46.7 mA; into the 1.8 uF stack (Table 1)
  //! that is 25.9 V/ms at the stack, 1.73 V/ms at the DAQ; rounded down.
  double max_slew_V_per_s = 1500.0;
  //! Ramp to 0 V after a fault or a stop: 20 ms from full scale, a third of the slew limit.
  double safe_ramp_V_per_s = 500.0;

  // SGS conditioner, 0..10 V over the 16 um nominal stroke (Section 4), read by a +-10 V ADC
  // (NI PCI-6229, Section 4). The stage reaches 14.6 um at most (Eq. 1), 9.1 V: the rail is never
  // reached in operation.
  double sgs_min_V = -0.25;        //!< below the conditioner's 0 V by more than noise and offset
  double sgs_max_V = 10.0;         //!< the conditioner's upper end
  double adc_full_scale_V = 10.0;  //!< the AI range (+-10 V)
  double rail_margin_V = 0.02;     //!< within this of full scale counts as clipped (~65 LSB)
  double sgs_noise_V = 0.05;       //!< noise allowance in the jump rule
  double jump_factor = 2.5;        //!< >= 2, see the header comment

  //! G = k_a / (k_a + k_m) = 70 / (70 + 6.78) (Eq. 1, Table 1, Section 2.2): the most SGS um a um
  //! of command can give (the jump rule's bound)
  double stage_gain = 0.9117;

  // Tracking, actuator response and authority.
  double tracking_error_um = 1.0;  //!< |S - y| in SGS micrometres
  double tracking_time_s = 0.1;    //!< must persist this long (a step settles in < 0.3 s)
  //! SGS um per um of command, lowest plausible. The twin gives 0.46 to 0.90 over the stroke,
  //! hysteresis included (docs/safety.md); a stack that does not answer its drive gives ~0.
  double response_gain_min = 0.4;
  double response_gain_max = 1.3;   //!< highest plausible (Eq. 1's 0.91 plus margin)
  double response_band_um = 0.8;    //!< absolute band around the window
  double response_time_s = 0.02;    //!< must persist this long (slewing and ringing settle)
  double saturation_time_s = 0.05;  //!< output pinned at output_max_V this long
  //! A swing of S - y this large between two turning points is a reversal. Ten times the
  //! settled error's range with the paper's gains (< 0.02 um); a phase step (79 nm) is smaller.
  double oscillation_band_um = 0.5;
  //! Reversals within oscillation_time_s that trip `oscillation`: four cycles. A stable loop's
  //! step rings at most three times beyond the band (kp 1, ki 0.5, kd 0.01 on the twin).
  std::uint32_t oscillation_reversals = 8;
  double oscillation_time_s = 0.1;  //!< the window the reversals must fall in

  //! Consecutive ticks that missed their next deadline.
  std::uint32_t max_consecutive_overruns = 3;
  //! Whether `overruns` trips (kOverrunTrip*): never (overruns are counted and reported only),
  //! always, or on hardware only. The supervisor takes "on hardware" as always; `run` and `serve`
  //! make it "never" on the twin, whose stage does not suffer when the host is late.
  std::uint32_t trip_on_overruns = 2;
};

inline constexpr std::uint32_t kOverrunTripNever = 0;
inline constexpr std::uint32_t kOverrunTripAlways = 1;
inline constexpr std::uint32_t kOverrunTripOnHardware = 2;

enum class FaultReason : std::uint8_t {
  kNone,
  kSgsNotFinite,
  kSgsRail,
  kSgsRange,
  kSgsJump,
  kTracking,
  kResponse,
  kSaturation,
  kOverruns,
  kDaqRead,
  kDaqWrite,
  kOutputNotFinite,
  kOscillation,  //!< appended: the logs' numbers of the others stay
};

//! Stable names for logs and JSON ("sgs-rail", ...); "none" for kNone.
const char* to_string(FaultReason reason) noexcept;

struct FaultRecord {
  FaultReason reason = FaultReason::kNone;
  std::uint64_t tick = 0;  //!< the tick whose inputs tripped the rule
  int channel = -1;        //!< 0..2, or -1 when the rule is not per channel
  double value = 0.0;      //!< the offending value (V, um or count)
  double limit = 0.0;      //!< the limit it crossed
};

enum class SupervisorState : std::uint8_t { kRunning, kStopping, kStopped, kFaulted };
const char* to_string(SupervisorState state) noexcept;

struct SupervisorInput {
  std::uint64_t tick = 0;
  double period_s = 1e-3;  //!< this tick's period (longer after skipped slots)
  Vec3 sgs_V{};            //!< the three AI as read
  Vec3 request_V{};        //!< the controller's DAQ volts
  Vec3 target_um{};        //!< S, actuator targets (SGS um)
  Vec3 feedback_um{};      //!< y, the SGS in um
  DaqStatus read_status = DaqStatus::kOk;
  DaqStatus previous_write_status = DaqStatus::kOk;
  bool previous_tick_overran = false;
  //! The controller is closing the loop (false: open-loop outputs, `piezoshift serve` with the
  //! servo off); the tracking and saturation rules apply only when true.
  bool closed_loop = true;
};

struct SupervisorOutput {
  Vec3 ao_V{};                    //!< what goes to the DAQ
  bool hold_integrators = false;  //!< freeze the controller's integral terms next tick
  bool limited = false;           //!< an output limit or the slew limit acted
  SupervisorState state = SupervisorState::kRunning;
};

//! Largest oscillation_reversals (the counter's fixed ring).
inline constexpr std::uint32_t kMaxOscillationReversals = 64;

//! The turning points of one channel's tracking error, with hysteresis: a reversal is a swing of
//! at least `band` back from the last extreme. Fixed-size, real-time safe.
class ReversalCounter {
 public:
  //! Feeds one tick's error and target; true when this tick completed `needed` reversals within
  //! `window_ticks` with the target steady between them.
  bool update(std::uint64_t tick, double error, double target, double band, std::uint32_t needed,
              std::uint64_t window_ticks) noexcept;
  void reset() noexcept { *this = ReversalCounter{}; }

 private:
  int direction_ = 0;  // +1 rising towards a peak, -1 falling towards a trough, 0 not yet known
  double extreme_ = 0.0;
  bool started_ = false;
  double target_at_reversal_ = 0.0;
  std::uint32_t count_ = 0;  // reversals in the ring (at most kMaxOscillationReversals)
  std::uint32_t next_ = 0;   // where the next reversal's tick goes
  std::array<std::uint64_t, kMaxOscillationReversals> ticks_{};
};

class SafetySupervisor {
 public:
  SafetySupervisor() { configure(SafetyLimits{}, 1e-3, {}); }
  //! Set-up. Throws std::invalid_argument on limits outside their ranges or inconsistent
  //! (safety_limits_problem(), safety_ranges.hpp).
  void configure(const SafetyLimits& limits, double sample_time_s,
                 const std::array<control::SignalScaling, control::kChannels>& scaling);

  //! Real-time safe. One tick: check, latch, shape the outputs.
  SupervisorOutput update(const SupervisorInput& in) noexcept;

  //! Real-time safe. Ramp to 0 V without a fault (end of run, SIGINT, SIGTERM).
  void request_stop() noexcept;
  //! Real-time safe. Unlatches a fault; outputs then follow the controller through the slew limit
  //! from where the ramp left them. False when no fault was latched.
  bool clear_fault() noexcept;
  //! Back to running from any state, outputs assumed at 0 V (set-up, after activate()).
  void reset() noexcept;

  SupervisorState state() const noexcept { return state_; }
  bool faulted() const noexcept { return state_ == SupervisorState::kFaulted; }
  const FaultRecord& fault() const noexcept { return fault_; }
  //! True when every output is at 0 V.
  bool outputs_at_zero() const noexcept;
  const Vec3& last_output_V() const noexcept { return last_ao_V_; }
  const SafetyLimits& limits() const noexcept { return limits_; }
  //! The per-tick jump bound (V) for channel i at period_s.
  double jump_limit_V(std::size_t i, double period_s) const noexcept;

 private:
  void latch(FaultReason reason, std::uint64_t tick, int channel, double value,
             double limit) noexcept;
  void check(const SupervisorInput& in) noexcept;

  SafetyLimits limits_{};
  double sample_time_s_ = 1e-3;
  std::array<control::SignalScaling, control::kChannels> scaling_{};
  Vec3 sgs_per_drive_{};  // g_i
  std::uint64_t tracking_ticks_ = 100;
  std::uint64_t response_ticks_ = 20;
  std::uint64_t saturation_ticks_ = 50;

  SupervisorState state_ = SupervisorState::kRunning;
  FaultRecord fault_{};
  Vec3 last_ao_V_{};
  Vec3 previous_sgs_V_{};
  bool have_previous_sgs_ = false;
  std::uint32_t consecutive_overruns_ = 0;
  std::array<std::uint64_t, control::kChannels> tracking_count_{};
  std::array<std::uint64_t, control::kChannels> response_count_{};
  std::array<std::uint64_t, control::kChannels> saturation_count_{};
  std::uint64_t oscillation_ticks_ = 100;
  std::array<ReversalCounter, control::kChannels> reversals_{};
};

}  // namespace piezoshift::runtime
