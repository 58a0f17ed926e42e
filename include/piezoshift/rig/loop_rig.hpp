#pragma once
// The guided calibration's rig on the real-time loop (`calibrate --daq comedi:/dev/comediN`, and
// the twin through the same loop, `--daq sim-rt`): runtime::ControlLoop runs in a thread of its
// own, in host mode, and the procedure (with the operator's prompt) in the caller's thread. They
// talk only through the loop's lock-free host link (runtime/host_link.hpp):
//
//   set_controller    kConfigure + the parameter set: applied between two ticks, bumplessly, or
//                     refused by the loop (the acknowledging sample's configure_problem)
//   drive_actuators   kActuators S (the PIDs alone, stage 2)
//   drive_points      kServoOn Z_d from open loop, kMoveTo Z_d when already on Z_d (stage 3)
//   rest              kServoOff then kOpenLoop 0 V (the supervisor's slew limit takes it down)
//   hold              kServoOff: the loop opens and holds the volts applied (clears a fault)
//   settle, measure   the loop's samples, drained from its ring: each command counts from the
//                     tick it was applied at (the samples carry its sequence number); a window is
//                     the mean SGS feedback over window_s of ticks, its start and end on the
//                     rig's clock (Unix time on hardware, LoopRigOptions::unix_time);
//                     saturated: a PID at its limit at the window's last tick; on the twin,
//                     the mean of its interferometer's readings
//   fault             the first latched fault any sample showed (sticky: kServoOn clears the
//                     loop's, never the rig's), or the loop's end
//
// Time: with a runtime::PacedClock (the twin, free-running) the rig lets the loop run exactly
// the ticks it waits for and holds it while it pushes commands, so a run is deterministic and
// as fast as the CPU allows; with the monotonic clock (hardware) the loop keeps its own time and
// the rig only watches it. The destructor stops the loop through its ramp to 0 V and joins it.
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <utility>

#include "piezoshift/rig/guided_rig.hpp"
#include "piezoshift/runtime/control_loop.hpp"
#include "piezoshift/runtime/daq_backend.hpp"
#include "piezoshift/runtime/paced_clock.hpp"
#include "piezoshift/runtime/realtime.hpp"
#include "piezoshift/runtime/safety_supervisor.hpp"

namespace piezoshift::rig {

struct LoopRigOptions {
  double rate_Hz = 1000.0;  //!< the loop's rate
  double window_s = 1.0;    //!< averaging window (the interferometer's static mode)
  //! Window times in Unix seconds (the loop's start read from the system clock, then the
  //! loop's own time): an interferometer log is stamped by the wall clock. Otherwise seconds
  //! since the loop started.
  bool unix_time = false;
  //! Ask for real-time treatment of the loop's thread (runtime/realtime.hpp) when the clock is.
  bool request_realtime = true;
  //! Polled by the loop (SIGINT/SIGTERM): nonzero stops it through its ramp to 0 V.
  const std::atomic<int>* stop_signal = nullptr;
};

class LoopRig final : public GuidedRig {
 public:
  //! daq: configured, not active (activated here, deactivated by the destructor). paced: the
  //! clock when it is a PacedClock (the same object), else null. Starts the loop's thread with
  //! the servo off at 0 V and params as its controller.
  LoopRig(runtime::DaqBackend& daq, runtime::LoopClock& clock, runtime::PacedClock* paced,
          const control::SemiClosedLoopParams& params, const runtime::SafetyLimits& limits,
          const LoopRigOptions& options);
  ~LoopRig() override;
  LoopRig(const LoopRig&) = delete;
  LoopRig& operator=(const LoopRig&) = delete;

  void set_controller(const control::SemiClosedLoopParams& params) override;
  control::SemiClosedLoopParams controller() const override { return params_; }
  void drive_actuators(const Vec3& s_um) override;
  void drive_points(const Vec3& zd_um) override;
  void settle(double duration_s) override;
  void rest(double settle_s) override;
  RigWindow measure() override;
  std::string fault() const override;
  bool replays() const override { return false; }

  //! What the real-time request got (empty refusals when it was not asked for).
  const runtime::RealtimeReport& realtime() const { return realtime_; }
  //! Stops the loop through its ramp to 0 V, waits for it and returns its result (once; the
  //! destructor does it when this was not called).
  runtime::LoopResult stop();
  //! The loop's timing statistics (complete after stop()).
  const runtime::LoopStats& loop_stats() const { return loop_->stats(); }
  //! Seconds on the rig's clock of the last tick seen.
  double clock_s() const;
  //! The last tick's sample the rig has taken.
  const runtime::HostSample& last_sample() const { return last_; }
  //! kServoOff: opens the loop holding the volts it applies (and clears a latched fault in the
  //! loop, not the rig's fault()); the next drive_points() closes it again bumplessly.
  void hold();
  //! Hands every sample the rig takes, in tick order on the caller's thread, to `each` (empty:
  //! none): a host that keeps its own account of the loop (procedures/loop_station.hpp).
  void set_observer(std::function<void(const runtime::HostSample&)> each) {
    observer_ = std::move(each);
  }
  //! Runs the next `ticks` ticks from the loop's present one, handing each tick's sample to
  //! `each` in tick order on the caller's thread as the rig takes it (a fringe scan's exposure:
  //! instrument/loop_scan_stage.hpp). Returns early, as settle() does, when the loop ends.
  void follow(std::uint64_t ticks, const std::function<void(const runtime::HostSample&)>& each);

 private:
  enum class Drive : std::uint8_t { kOpenLoop, kActuators, kPoints };
  //! Pushes cmd with the next sequence number and waits for the tick that applied it.
  void command(runtime::HostCommand cmd);
  //! Takes the loop's samples until done() (or the loop ended); on a PacedClock lets the loop
  //! run up to the tick horizon (never past the tick the rig waits for).
  template <typename Done>
  void wait(Done done, std::uint64_t horizon_tick);
  //! Takes whatever the ring holds, then waits for one more sample: the loop's present tick
  //! (a ring that a long prompt let overflow holds old ones).
  void catch_up();
  //! Takes the samples waiting in the ring (old ones, when it overflowed); true when there were.
  bool take_waiting();
  void take(const runtime::HostSample& h);
  std::uint64_t next_tick() const { return seen_any_ ? last_.tick + 1 : 0; }
  std::uint64_t ticks_of(double duration_s) const;

  runtime::DaqBackend& daq_;
  runtime::PacedClock* paced_;
  control::SemiClosedLoopParams params_;
  LoopRigOptions options_;
  runtime::HostLink link_;
  std::unique_ptr<runtime::ControlLoop> loop_;
  std::thread thread_;
  std::atomic<bool> started_{false};  // the real-time request is done
  std::atomic<bool> finished_{false};
  runtime::LoopResult result_{};
  runtime::RealtimeReport realtime_{};
  bool stopped_ = false;
  double clock_origin_s_ = 0.0;  // set by the loop's thread before started_
  std::atomic<int> stop_{0};

  std::uint64_t sequence_ = 0;
  Drive drive_ = Drive::kOpenLoop;
  bool seen_any_ = false;
  runtime::HostSample last_{};
  std::string fault_;
  // The window being summed (window_ticks_ 0: none).
  std::uint64_t window_from_ = 0;
  std::uint64_t window_ticks_ = 0;
  std::uint64_t window_n_ = 0;
  double window_start_s_ = 0.0;
  Vec3 window_sgs_V_{};
  Vec3 window_ifm_um_{};
  bool window_truth_ = true;
  // The ticks follow() hands on (follow_ null: none).
  const std::function<void(const runtime::HostSample&)>* follow_ = nullptr;
  std::uint64_t follow_from_ = 0;
  std::uint64_t follow_to_ = 0;  // one past the last
  std::function<void(const runtime::HostSample&)> observer_;
};

}  // namespace piezoshift::rig
