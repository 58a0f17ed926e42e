#pragma once
// The data-acquisition interface between the real-time loop and the hardware (or its twin), in the
// spirit of ros2_control's hardware_interface:
//
//   configure()   set-up: open the device, look up ranges and calibration     may throw, allocates
//   activate()    outputs to 0 V, ready to cycle                               may throw
//   per tick:     read(t)  -> three AI volts (the SGS conditioners)            real-time safe
//                 write(t) <- three AO volts (to the x15 amplifiers)           real-time safe
//   deactivate()  outputs to 0 V and applied; configure()d state is kept       noexcept
//
// Timing contract, the same for every backend so that the twin sees what the board sees: one
// transaction per tick at the start of read(). The AO values staged by the previous write() go
// out first, then the AI are sampled. So the samples of tick k reflect the outputs held during
// the period before it, and the outputs computed in tick k act from tick k+1 on: a fixed one-period
// transport delay (Comedi: one comedi_do_insnlist with three writes then three reads).
//
// read() and write() never throw and never allocate; they return a status. A non-kOk status is a
// fault for the safety supervisor.
//
// Optional: a digital trigger output (a camera's hardware trigger; default: none). The loop stages
// the line's level before the tick's read() only when it changes (control_loop.hpp's trigger
// pulse); the level goes out in the same transaction as the staged AO, so a rising edge staged in
// tick k happens at tick k's scheduled time, and the line keeps its level until staged again.
// activate() and deactivate() leave it low.
#include <cstdint>
#include <string>

#include "piezoshift/control/vec3.hpp"

namespace piezoshift::runtime {

using control::Vec3;

enum class DaqStatus : std::uint8_t {
  kOk,
  kError,     //!< the transaction failed (driver error); the AI values are not valid
  kClamped,   //!< write(): a value outside the output range was clamped before conversion
  kInactive,  //!< read()/write() outside activate()..deactivate()
};

//! A rising edge of the trigger line: the tick whose transaction raised it and its scheduled time.
struct TriggerEdge {
  std::uint64_t tick = 0;
  std::int64_t since_start_ns = 0;
};

//! Where a tick is on the loop's time line.
struct CycleTime {
  std::uint64_t tick = 0;           //!< 0 for the first tick after activate()
  std::int64_t since_start_ns = 0;  //!< scheduled time of this tick since the loop started
  std::int64_t period_ns = 0;  //!< scheduled time since the previous tick (skipped slots count)
};

class DaqBackend {
 public:
  virtual ~DaqBackend() = default;

  //! Set-up: open and query the device. Throws core::InputError naming the device when it cannot.
  virtual void configure() = 0;
  //! Outputs to 0 V, ready for read()/write(). Throws on a device error.
  virtual void activate() = 0;
  //! Outputs to 0 V (applied, not staged); safe to call twice. Never throws.
  virtual void deactivate() noexcept = 0;

  //! Real-time safe. Applies the staged outputs, then samples the three AI into ai_V.
  virtual DaqStatus read(const CycleTime& t, Vec3& ai_V) noexcept = 0;
  //! Real-time safe. Stages the three AO volts; they go out at the start of the next read().
  virtual DaqStatus write(const CycleTime& t, const Vec3& ao_V) noexcept = 0;

  //! Set-up: a short name for logs and summaries ("sim", "comedi:/dev/comedi0").
  virtual std::string name() const = 0;

  //! For reports after the loop: the device's own text for the last transaction that failed
  //! (read() returned kError), or empty.
  virtual std::string device_error() const { return {}; }
  //! For reports after deactivate(): empty when the outputs were set to 0 V, else why they could
  //! not be (the device's error); the amplifier must then be switched off by hand.
  virtual std::string safe_state_error() const { return {}; }

  //! Real-time safe. Ground truth at the measurement points P1..P3 (um), where the backend knows
  //! it (the twin: true displacement and the interferometer's reading). False on hardware.
  virtual bool truth(Vec3& /*z_um*/, Vec3& /*interferometer_um*/) const noexcept { return false; }
  //! Real-time safe. What the Fizeau's fringes see beyond the plate's piston [nm]: the twin's
  //! cavity drift when twin.cavity.in_fringes (plant/fizeau_cavity.hpp), else 0; 0 on hardware.
  virtual double fringe_drift_nm() const noexcept { return 0.0; }

  //! Set-up: the backend drives a digital trigger output (default: none).
  virtual bool has_trigger_line() const noexcept { return false; }
  //! Real-time safe. Stages the trigger line's level: it goes out at the start of the next read(),
  //! with the staged AO, and holds until staged again. Ignored without a line.
  virtual void stage_trigger_line(bool /*high*/) noexcept {}
  //! Owner thread, lock-free: the oldest rising edge not yet taken, where the backend sees its own
  //! line (the twin: its wire to the twin camera). False when there is none; always on hardware,
  //! where the wire is a cable.
  virtual bool take_trigger_edge(TriggerEdge& /*edge*/) noexcept { return false; }
};

}  // namespace piezoshift::runtime
