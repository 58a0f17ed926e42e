#pragma once
// A stage behind the real-time loop, driven from a program (Python's piezoshift.Stage,
// docs/python.md) as a GCS client drives `piezoshift serve`: the loop stack (loop_stack.hpp:
// the twin at the loop's rate, or a Comedi board; --fault specs on the twin), the controller's
// calibration (loop_setup.hpp) and rig::LoopRig, which runs the loop on its own thread behind the
// host link and stops it through its ramp to 0 V. On top, what `serve`'s GCS commands offer:
//
//   servo(on)        SVO: on closes the loop bumplessly at the pose the gauges show (MOV? :=
//                    POS?); off opens it holding the volts applied; either clears a latched
//                    fault
//   move(pose)       MOV: the whole pose, checked against the stage's reach (StageModel); the
//                    servo must be on
//   on target        ONT?: the servo on, the last move applied and |position - target| within
//                    on_target_um (Z) and on_target_urad (tip, tilt) for settle_s, every axis
//   position         POS?: the pose the strain gauges say (StageModel::pose_from_sgs)
//   record, read     DRC/RTR/DRR? (station_recorder.hpp), from the loop's present tick
//   fault            the fault the safety supervisor latched, by its rule's name; move() and
//                    wait_on_target() throw StationFaulted while it holds, servo(true) when it
//                    latches again at once (a gauge still open)
//   close            the loop's ramp to 0 V, then its thread joined (idempotent; the destructor)
//
// Time: every wait counts the loop's ticks, so a timeout is loop time (on the monotonic clock it
// is wall time too). With free_run the twin's loop runs only while the station waits (a
// runtime::PacedClock): deterministic, and as fast as the CPU allows.
// Not thread-safe: one caller at a time (Python's Stage holds a mutex).
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "piezoshift/calibration/loop_calibration.hpp"
#include "piezoshift/host/stage_model.hpp"
#include "piezoshift/plant/simulation_cost.hpp"
#include "piezoshift/procedures/loop_stack.hpp"
#include "piezoshift/procedures/station_recorder.hpp"
#include "piezoshift/rig/loop_rig.hpp"
#include "piezoshift/runtime/safety_ranges.hpp"

namespace piezoshift::procedures {

struct LoopStationOptions {
  //! "sim-rt" (or "sim", as `serve` spells it): the twin at the loop's rate; "comedi[:DEVICE]"
  std::string daq = "sim-rt";
  //! The twin only: its loop runs only while the station waits (deterministic, not real time)
  bool free_run = false;
  double rate_Hz = 1000.0;  //!< checked: check_loop_rate
  std::uint64_t seed = 1;   //!< the twin's, and its start-up calibration's
  std::string config_path;  //!< TOML configuration with [safety] ("" built in)
  //! A calibration file ("" none: `calibration` when given, else resolve_calibration's choice)
  std::string calibration_path;
  //! A controller in memory (Python's calibrate_from_fringes()["controller"]), checked at the
  //! loop's rate; ignored when calibration_path is given
  std::optional<calibration::LoopCalibration> calibration;
  std::vector<std::string> faults;           //!< --fault specs (the twin only)
  std::optional<std::int64_t> max_overruns;  //!< absent: the installation's [safety]
  double on_target_um = 0.01;                //!< as `serve --on-target-um`
  double on_target_urad = 0.5;               //!< as `serve --on-target-urad`
  double settle_s = 0.01;                    //!< as `serve --settle-s`
  bool request_realtime = true;              //!< SCHED_FIFO, pinning and mlockall for the loop
  double max_physics_steps = plant::kDefaultPhysicsStepBudget;  //!< the start-up calibration
};

//! A fault the safety supervisor latched.
struct StationFault {
  std::string name;  //!< the rule ("sgs-rail", runtime::to_string(FaultReason))
  int channel = -1;  //!< 1..3, or -1 when the rule is not per channel
  std::uint64_t tick = 0;
  double t_s = 0.0;  //!< loop time of the tick that showed it
  //! "sgs-rail on channel 1 at t = 0.2000 s (tick 200)"
  std::string description() const;
};

//! Thrown by a call that finds a fault latched; servo(true) clears it.
class StationFaulted : public std::runtime_error {
 public:
  explicit StationFaulted(StationFault fault);
  const StationFault& fault() const noexcept { return fault_; }

 private:
  StationFault fault_;
};

//! wait_on_target() or read_recording() ran out of (loop) time.
class StationTimeout : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class LoopStation {
 public:
  //! Builds the stack, resolves the calibration and starts the loop, servo off at 0 V. Throws
  //! core::InputError naming the option, file or device at fault.
  explicit LoopStation(const LoopStationOptions& options);
  ~LoopStation();
  LoopStation(const LoopStation&) = delete;
  LoopStation& operator=(const LoopStation&) = delete;

  void servo(bool on);
  bool servo_on() const noexcept { return servo_on_; }
  //! The whole pose [Z um, tip urad, tilt urad]; core::InputError naming why it is out of
  //! reach; std::logic_error with the servo off.
  void move(const host::AxisValues& pose);
  //! Returns once on target; StationTimeout after timeout_s of loop time, naming the position,
  //! the target and the band; StationFaulted when a fault latches.
  void wait_on_target(double timeout_s);
  bool on_target() const noexcept;

  //! Takes the loop's samples up to its present tick.
  void update();
  //! The pose the gauges say at the last tick taken (update() first for the present one).
  host::AxisValues position() const;
  host::AxisValues target() const noexcept { return target_; }
  //! The twin's interferometer as a pose at the last tick taken; NaN on hardware.
  host::AxisValues interferometer() const;
  //! The DAQ's output volts at the last tick taken (0 V once closed).
  control::Vec3 output_V() const;
  //! Seconds on the loop's clock at the last tick taken.
  double time_s() const;

  //! Records `points` points of `signals` (empty: all), one every `every` ticks, from the next
  //! tick on (core::InputError for bad arguments, station_recorder.hpp).
  void record(std::size_t points, std::uint64_t every, std::vector<RecorderSignal> signals);
  //! Waits until the recording is complete and returns it; StationTimeout after timeout_s of
  //! loop time; std::logic_error when nothing was recorded.
  const Recording& read_recording(double timeout_s);

  //! The fault latched now, if any.
  const std::optional<StationFault>& fault() const noexcept { return fault_; }

  //! Ramps the outputs to 0 V and joins the loop's thread. Idempotent.
  void close();
  bool closed() const noexcept { return closed_; }

  const host::StageModel& model() const noexcept { return *model_; }
  std::string daq_name() const { return stack_->name(); }
  double rate_Hz() const noexcept { return rate_Hz_; }
  const std::string& calibration_source() const noexcept { return calibration_source_; }
  const runtime::SafetyLimits& safety() const noexcept { return safety_; }
  const runtime::RealtimeReport& realtime() const { return rig_->realtime(); }
  //! The twin when the daq is, else null.
  runtime::SimBackend* sim() { return stack_->sim(); }

 private:
  void take(const runtime::HostSample& h);
  void check_open() const;
  void throw_if_faulted() const;
  std::uint64_t ticks_of(double duration_s) const;
  //! Lets the loop run (or watches it run) for about `ticks` more ticks.
  void run_ticks(std::uint64_t ticks);

  double rate_Hz_;
  double on_target_um_;
  double on_target_urad_;
  std::uint64_t settle_ticks_;
  std::string calibration_source_;
  runtime::SafetyLimits safety_{};
  std::unique_ptr<LoopStack> stack_;
  std::unique_ptr<host::StageModel> model_;
  std::unique_ptr<rig::LoopRig> rig_;
  bool closed_ = false;

  bool servo_on_ = false;
  host::AxisValues target_{};
  //! Latches the fault h shows, if none is latched yet.
  void latch_fault(const runtime::HostSample& h);
  //! rig::LoopRig::hold(), and the fault it clears (SVO, either value, clears a latch).
  void open_loop();

  // Until the rig has a command applied, its samples count no settling (a move) or show no new
  // fault (a servo change, which clears the latch: samples before it show the old one).
  bool moving_ = false;
  bool clearing_ = false;
  std::uint64_t settled_ = 0;  // consecutive on-target ticks since the last move applied
  std::optional<StationFault> fault_;
  bool have_sample_ = false;
  runtime::HostSample last_{};
  StationRecorder recorder_;
};

}  // namespace piezoshift::procedures
