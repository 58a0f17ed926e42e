#pragma once
// The real-time loop's door to a host (the GCS server of `piezoshift serve`, docs/gcs.md): two
// lock-free rings, so a host thread never blocks the loop and the loop never waits for the host.
//
//   host -> loop   HostCommand    at most a few per tick are applied, at the start of the tick,
//                                 before the DAQ read; a full ring refuses the push (host side)
//   loop -> host   HostSample     one per tick, after the DAQ write; a full ring drops the sample
//                                 and counts it (the host drains every turn of its poll loop)
//
// What the loop does with a command (ControlLoop::run, host mode):
//   kMoveTo      servo on: Z_d := zd_um (the desired displacements of P1..P3)
//   kServoOn     clears a latched fault, then closes the loop bumplessly: every PID restarts from
//                the command the output already holds (reset_to) and Z_d := zd_um
//   kServoOff    clears a latched fault, then opens the loop: the open-loop outputs start at the
//                volts already applied, so nothing moves
//   kOpenLoop    servo off: the DAQ outputs := ao_V (through the safety supervisor's limits)
//   kWave        starts or stops one wave generator (wave_generator.hpp); it plays into Z_d while
//                the servo is on and no fault is latched, and stops otherwise
//   kActuators   the PIDs alone on the SGS targets S := actuator_target_um (calibration stage 2,
//                the guided calibration's LoopRig); bumpless from open loop; kServoOn returns to
//                Z_d
//   kConfigure   pops the next parameter set from `params` and makes it the controller's,
//                bumplessly, when the loop can run it (ControlCycle::try_configure, at the loop's
//                sample time); otherwise nothing changes and every later sample's
//                configure_problem says why, until the next kConfigure. The one safe point to
//                change parameters is between two ticks, in the loop's thread
// Every sample carries the sequence number of the last command applied, so the host knows when
// its command has reached the loop.
#include <cstdint>

#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/control/vec3.hpp"
#include "piezoshift/runtime/spsc_ring.hpp"
#include "piezoshift/runtime/wave_generator.hpp"

namespace piezoshift::runtime {

using control::Vec3;

struct HostCommand {
  enum class Kind : std::uint8_t {
    kMoveTo,
    kServoOn,
    kServoOff,
    kOpenLoop,
    kWave,
    kActuators,
    kConfigure
  };
  Kind kind = Kind::kMoveTo;
  std::uint64_t sequence = 0;  //!< set by the host, increasing
  Vec3 zd_um{};                //!< kMoveTo, kServoOn: Z_d of P1..P3
  Vec3 actuator_target_um{};   //!< kActuators: S, the SGS targets of actuators 1..3
  Vec3 ao_V{};                 //!< kOpenLoop: DAQ volts per channel
  WaveCommand wave{};          //!< kWave
};

struct HostSample {
  std::uint64_t tick = 0;
  double t_s = 0.0;                    //!< scheduled time since the loop started
  std::uint64_t applied_sequence = 0;  //!< the last HostCommand applied (0: none yet)
  Vec3 zd_um{};                        //!< Z_d in force (closed loop)
  Vec3 target_um{};                    //!< S = A p(Z_d), actuator targets (closed loop)
  Vec3 sgs_V{};                        //!< the three AI as read
  Vec3 ao_V{};                         //!< the outputs sent to the DAQ
  Vec3 interferometer_um{};            //!< the twin's interferometer at P1..P3 (has_truth)
  Vec3 truth_um{};                     //!< the twin's true displacement of P1..P3 (has_truth)
  double fringe_drift_nm = 0.0;        //!< the fringes' piston beyond the plate's (DaqBackend's)
  double wake_latency_us = 0.0;        //!< wake-up - deadline of this tick
  std::uint8_t overrun = 0;            //!< this tick's work ended after the next deadline
  std::uint8_t closed_loop = 0;        //!< servo on
  std::uint8_t actuators = 0;          //!< closed loop on S alone (kActuators)
  std::uint8_t saturated_mask = 0;     //!< bit i: PID i at its output limit (closed loop)
  std::uint8_t has_truth = 0;          //!< the backend is the twin
  std::uint8_t state = 0;              //!< SupervisorState as a number
  std::uint8_t fault_reason = 0;       //!< FaultReason as a number (0 = none)
  std::int8_t fault_channel = -1;
  std::uint8_t wave_running = 0;  //!< bit g: wave generator g runs (WaveGenerator::running_mask)
  //! control::ParamsProblem of the last kConfigure as a number (0: applied, or none yet)
  std::uint8_t configure_problem = 0;
};

struct HostLink {
  static constexpr std::size_t kCommandCapacity = 64;
  //! 4 s at 1 kHz: the host drains it every few ms; a stalled host costs samples, not the loop.
  static constexpr std::size_t kSampleCapacity = 4096;
  //! Commands applied per tick at most, so that a burst cannot lengthen one tick much.
  static constexpr int kMaxCommandsPerTick = 8;

  SpscRing<HostCommand> commands{kCommandCapacity};
  //! kConfigure's parameter sets, pushed before their command (a few are ever in flight).
  SpscRing<control::SemiClosedLoopParams> params{4};
  SpscRing<HostSample> samples{kSampleCapacity};
};

}  // namespace piezoshift::runtime
