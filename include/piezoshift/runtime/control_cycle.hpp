#pragma once
// One control tick, the only one piezoshift has: `run`, `serve`, `simulate`, the simulated bench
// (the calibration procedures, the paper's experiments, `reproduce`) all close the loop through
// it, against any DAQ backend (the twin is one more backend, daq_backend.hpp). Per tick:
//
//   ai = daq.read(t)                     the outputs staged at the previous tick go out, then the
//                                        three AI are sampled (daq_backend.hpp's timing contract)
//   c  = by drive mode (drive_points, drive_actuators, drive_open_loop):
//          points     controller.update(Z_d, ai)           feedforward (Eq. 8) + PIDs (Eqs. 6, 7)
//          actuators  controller.update_actuators(S, ai)   the PIDs alone (calibration stages 1, 2)
//          open loop  c.dac_V = V                          volts straight to the amplifiers
//   s  = supervisor.update(ai, c, statuses, previous tick overran)
//   controller.hold_integrators(s.hold_integrators)
//   daq.write(t, s.ao_V)
//
// Hand-overs are bumpless: going from open loop to a closed mode, each PID restarts from the
// command the outputs already hold. A latched fault ramps the outputs to 0 V (the supervisor)
// until clear_fault(), after which the PIDs restart from 0 V and the outputs follow them through
// the slew limit from where the ramp left them.
//
// step() and try_configure() are real-time safe: no heap, no exceptions, no I/O. Construction is
// set-up (it throws std::invalid_argument on parameters or limits the loop cannot run).
#include <cstdint>
#include <string>
#include <string_view>

#include "piezoshift/control/parameter_check.hpp"
#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/runtime/daq_backend.hpp"
#include "piezoshift/runtime/safety_supervisor.hpp"

namespace piezoshift::runtime {

enum class DriveMode : std::uint8_t { kOpenLoop, kActuators, kPoints };
const char* to_string(DriveMode mode) noexcept;

//! The sentence for a parameter set try_configure() refused, for whoever reports it (source: who
//! asked, e.g. "bench"): "<source>: the loop refused the controller: <problem>". Not real-time.
std::string refused_controller_message(std::string_view source, control::ParamsProblem problem);

//! What one tick saw and did.
struct CycleSample {
  std::uint64_t tick = 0;
  DriveMode mode = DriveMode::kOpenLoop;
  // What the tick followed: the field of its mode; the other two are zero.
  Vec3 zd_um{};               //!< points: Z_d, the desired displacements of P1..P3 [um]
  Vec3 actuator_target_um{};  //!< actuators: S, the SGS targets of actuators 1..3 [um]
  Vec3 open_loop_V{};         //!< open loop: the volts requested per DAQ channel [V]
  Vec3 ai_V{};                //!< the AI as read
  //! The controller's tick (open loop: dac_V = the requested volts, feedback_um from the AI,
  //! target_um = feedback_um).
  control::ControllerOutput controller{};
  SupervisorOutput supervisor{};  //!< ao_V is what was written
  DaqStatus read_status = DaqStatus::kOk;
  DaqStatus write_status = DaqStatus::kOk;
};

class ControlCycle {
 public:
  //! params.sample_time_s must be the loop's period (the PIDs' gains are rescaled to it).
  ControlCycle(const control::SemiClosedLoopParams& params, const SafetyLimits& limits);

  //! Real-time safe. Replaces the controller's parameters when control::params_problem() finds
  //! none at the loop's sample time, and the PIDs restart from the command the outputs hold
  //! (bumpless); otherwise nothing changes. Returns the problem (kNone: applied).
  control::ParamsProblem try_configure(const control::SemiClosedLoopParams& params) noexcept;

  //! Real-time safe. What the next ticks follow, one call per drive mode; bumpless from open
  //! loop to a closed mode.
  //! Open loop: ao_V, the volts per DAQ channel (through the supervisor's limits).
  void drive_open_loop(const Vec3& ao_V) noexcept;
  //! The PIDs alone on target_um, S, the SGS targets of actuators 1..3.
  void drive_actuators(const Vec3& target_um) noexcept;
  //! The full controller on zd_um, Z_d, the desired displacements of P1..P3.
  void drive_points(const Vec3& zd_um) noexcept;
  //! Real-time safe. Every PID restarts from the command the outputs hold (servo on).
  void restart_from_outputs() noexcept;
  //! Real-time safe. One tick (see the header comment).
  const CycleSample& step(DaqBackend& daq, const CycleTime& t, bool previous_tick_overran) noexcept;

  //! Real-time safe. Unlatches a fault; the PIDs restart from 0 V. False when none was latched.
  bool clear_fault() noexcept;
  //! Real-time safe. Ramps to 0 V without a fault.
  void request_stop() noexcept { supervisor_.request_stop(); }
  //! Back to the start: supervisor running, outputs assumed at 0 V, PIDs from 0 V, open loop at
  //! 0 V.
  void reset() noexcept;

  DriveMode mode() const noexcept { return mode_; }
  const CycleSample& last() const noexcept { return last_; }
  const control::SemiClosedLoopController& controller() const noexcept { return controller_; }
  const SafetySupervisor& supervisor() const noexcept { return supervisor_; }
  const control::SemiClosedLoopParams& params() const noexcept { return controller_.params(); }

 private:
  //! The command (um) that produced the outputs now held.
  Vec3 held_command_um() const noexcept;
  //! Switches to mode (bumpless from open loop) with every demand at zero.
  void enter(DriveMode mode) noexcept;

  control::SemiClosedLoopController controller_;
  SafetySupervisor supervisor_;
  DriveMode mode_ = DriveMode::kOpenLoop;
  // The demand of mode_ (the other two zero), as CycleSample's.
  Vec3 zd_um_{};
  Vec3 actuator_target_um_{};
  Vec3 open_loop_V_{};
  DaqStatus previous_write_ = DaqStatus::kOk;
  CycleSample last_{};
};

}  // namespace piezoshift::runtime
