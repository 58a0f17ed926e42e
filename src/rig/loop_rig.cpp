#include "piezoshift/rig/loop_rig.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/core.h>

namespace piezoshift::rig {

namespace {

// Ticks a PacedClock is let run ahead of the rig at most: a quarter of the sample ring, so that
// the loop never drops a sample the rig is about to take.
constexpr std::uint64_t kPacedChunkTicks = runtime::HostLink::kSampleCapacity / 4;

}  // namespace

LoopRig::LoopRig(runtime::DaqBackend& daq, runtime::LoopClock& clock, runtime::PacedClock* paced,
                 const control::SemiClosedLoopParams& params, const runtime::SafetyLimits& limits,
                 const LoopRigOptions& options)
    : daq_(daq), paced_(paced), params_(params), options_(options) {
  if (!(options.window_s > 0.0) || !std::isfinite(options.window_s))
    throw std::invalid_argument("loop rig: window_s must be > 0");
  runtime::LoopConfig config;
  config.rate_Hz = options.rate_Hz;
  config.duration_s = std::numeric_limits<double>::infinity();
  config.stop_signal = &stop_;
  // A fault holds the outputs at 0 V until the rig stops the loop: the procedure reads it.
  config.stop_when_safe_after_fault = false;
  config.host = &link_;
  loop_ = std::make_unique<runtime::ControlLoop>(config, params, limits, daq, clock,
                                                 runtime::SetpointProfile{});
  params_.sample_time_s = static_cast<double>(loop_->period_ns()) * 1e-9;
  daq_.activate();
  const bool rt = options.request_realtime && clock.real_time();
  thread_ = std::thread([this, rt] {
    if (rt)
      realtime_ = runtime::request_realtime(runtime::RealtimeRequest{});
    if (options_.unix_time)
      clock_origin_s_ =
          std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch())
              .count();
    started_.store(true, std::memory_order_release);
    started_.notify_one();
    result_ = loop_->run();
    finished_.store(true, std::memory_order_release);
  });
  started_.wait(false, std::memory_order_acquire);
}

LoopRig::~LoopRig() {
  stop();
}

runtime::LoopResult LoopRig::stop() {
  if (!stopped_) {
    stopped_ = true;
    stop_.store(1, std::memory_order_relaxed);
    if (paced_ != nullptr)
      paced_->open();
    thread_.join();
    daq_.deactivate();
    runtime::HostSample h;
    while (link_.samples.try_pop(h))
      take(h);
  }
  return result_;
}

double LoopRig::clock_s() const {
  return clock_origin_s_ + last_.t_s;
}

std::uint64_t LoopRig::ticks_of(double duration_s) const {
  const double ticks = duration_s * options_.rate_Hz;
  return ticks > 0.0 ? static_cast<std::uint64_t>(std::llround(ticks)) : 0;
}

void LoopRig::take(const runtime::HostSample& h) {
  seen_any_ = true;
  last_ = h;
  if (h.fault_reason != 0 && fault_.empty()) {
    const auto reason = static_cast<runtime::FaultReason>(h.fault_reason);
    fault_ = h.fault_channel >= 0
                 ? fmt::format("the safety supervisor tripped ({}, channel {}, at {:.3f} s)",
                               runtime::to_string(reason), h.fault_channel + 1, clock_s())
                 : fmt::format("the safety supervisor tripped ({}, at {:.3f} s)",
                               runtime::to_string(reason), clock_s());
  }
  if (observer_)
    observer_(h);
  if (follow_ != nullptr && h.tick >= follow_from_ && h.tick < follow_to_)
    (*follow_)(h);
  if (window_ticks_ == 0)
    return;
  if (h.tick < window_from_ || h.tick >= window_from_ + window_ticks_)
    return;
  if (window_n_ == 0)
    window_start_s_ = clock_s();
  ++window_n_;
  for (std::size_t i = 0; i < 3; ++i) {
    window_sgs_V_[i] += h.sgs_V[i];
    window_ifm_um_[i] += h.interferometer_um[i];
  }
  window_truth_ = window_truth_ && h.has_truth != 0;
}

template <typename Done>
void LoopRig::wait(Done done, std::uint64_t horizon_tick) {
  runtime::HostSample h;
  for (;;) {
    bool took = false;
    while (!done() && link_.samples.try_pop(h)) {
      take(h);
      took = true;
    }
    if (done())
      return;
    if (finished_.load(std::memory_order_acquire)) {
      while (link_.samples.try_pop(h))
        take(h);
      if (!done() && fault_.empty())
        fault_ = result_.stop_reason == runtime::StopReason::kSignal
                     ? fmt::format(
                           "stopped by a signal at {:.3f} s, the outputs ramped to 0 V "
                           "(the session is recorded: run the same command to resume)",
                           clock_s())
                     : fmt::format("the control loop stopped ({}) at {:.3f} s",
                                   runtime::to_string(result_.stop_reason), clock_s());
      return;
    }
    if (options_.stop_signal != nullptr) {
      if (const int sig = options_.stop_signal->load(std::memory_order_relaxed); sig != 0)
        stop_.store(sig, std::memory_order_relaxed);
    }
    if (paced_ != nullptr) {
      const std::uint64_t to =
          std::min(std::max(horizon_tick, next_tick()), next_tick() + kPacedChunkTicks);
      paced_->allow_until_ns(static_cast<std::int64_t>(to) * loop_->period_ns());
    }
    if (!took)
      std::this_thread::sleep_for(paced_ != nullptr ? std::chrono::microseconds(20)
                                                    : std::chrono::milliseconds(1));
  }
}

bool LoopRig::take_waiting() {
  runtime::HostSample h;
  bool waiting = false;
  while (link_.samples.try_pop(h)) {
    take(h);
    waiting = true;
  }
  return waiting;
}

void LoopRig::catch_up() {
  take_waiting();
  const std::uint64_t after = next_tick();
  wait([&] { return seen_any_ && last_.tick >= after; }, after);
}

void LoopRig::command(runtime::HostCommand cmd) {
  cmd.sequence = ++sequence_;
  // The loop applies a few commands per tick from a ring of 64: a full ring is a stalled loop.
  wait([&] { return link_.commands.try_push(cmd); }, next_tick());
  const std::uint64_t seq = cmd.sequence;
  wait([&] { return seen_any_ && last_.applied_sequence >= seq; }, next_tick());
}

void LoopRig::set_controller(const control::SemiClosedLoopParams& params) {
  control::SemiClosedLoopParams p = params;
  p.sample_time_s = params_.sample_time_s;
  wait([&] { return link_.params.try_push(p); }, next_tick());
  runtime::HostCommand c;
  c.kind = runtime::HostCommand::Kind::kConfigure;
  command(c);
  // The sample that acknowledges the command says whether the loop took the set.
  const auto problem = static_cast<control::ParamsProblem>(last_.configure_problem);
  if (problem != control::ParamsProblem::kNone)
    throw std::invalid_argument(runtime::refused_controller_message("loop rig", problem));
  params_ = p;
}

void LoopRig::drive_actuators(const Vec3& s_um) {
  runtime::HostCommand c;
  c.kind = runtime::HostCommand::Kind::kActuators;
  c.actuator_target_um = s_um;
  command(c);
  drive_ = Drive::kActuators;
}

void LoopRig::drive_points(const Vec3& zd_um) {
  runtime::HostCommand c;
  // kMoveTo only moves a loop already on Z_d; kServoOn closes it bumplessly from open loop or
  // from the actuator targets.
  c.kind = drive_ == Drive::kPoints ? runtime::HostCommand::Kind::kMoveTo
                                    : runtime::HostCommand::Kind::kServoOn;
  c.zd_um = zd_um;
  command(c);
  drive_ = Drive::kPoints;
}

void LoopRig::hold() {
  runtime::HostCommand c;
  c.kind = runtime::HostCommand::Kind::kServoOff;
  command(c);
  drive_ = Drive::kOpenLoop;
}

void LoopRig::settle(double duration_s) {
  catch_up();
  const std::uint64_t until = last_.tick + ticks_of(duration_s);
  wait([&] { return last_.tick >= until; }, until);
}

void LoopRig::follow(std::uint64_t ticks,
                     const std::function<void(const runtime::HostSample&)>& each) {
  // Samples waiting in the ring may be old ones (as measure()): after them, the present tick.
  if (take_waiting() || !seen_any_)
    catch_up();
  follow_from_ = next_tick();
  follow_to_ = follow_from_ + ticks;
  follow_ = &each;
  if (ticks > 0) {
    const std::uint64_t last = follow_to_ - 1;
    wait([&] { return last_.tick >= last; }, last);
  }
  follow_ = nullptr;
}

void LoopRig::rest(double settle_s) {
  // The servo off holds the volts applied; open loop at 0 V then goes down through the
  // supervisor's slew limit. Both in one tick.
  runtime::HostCommand off;
  off.kind = runtime::HostCommand::Kind::kServoOff;
  runtime::HostCommand zero;
  zero.kind = runtime::HostCommand::Kind::kOpenLoop;
  off.sequence = ++sequence_;
  zero.sequence = ++sequence_;
  wait([&] { return link_.commands.try_push(off); }, next_tick());
  wait([&] { return link_.commands.try_push(zero); }, next_tick());
  const std::uint64_t seq = zero.sequence;
  wait([&] { return seen_any_ && last_.applied_sequence >= seq; }, next_tick());
  drive_ = Drive::kOpenLoop;
  settle(settle_s);
}

RigWindow LoopRig::measure() {
  // Samples waiting in the ring may be old ones (a ring that overflowed keeps its oldest): after
  // them, the loop's present tick. A paced loop leaves none.
  if (take_waiting())
    catch_up();
  window_ticks_ = std::max<std::uint64_t>(1, ticks_of(options_.window_s));
  window_n_ = 0;
  window_sgs_V_ = Vec3{};
  window_ifm_um_ = Vec3{};
  window_truth_ = true;
  // The next whole window of the interferometer's static mode, whose windows follow each other
  // from the loop's start (as the twin's do: the same timing as BenchRig's).
  const std::uint64_t after = next_tick();
  window_from_ = (after + window_ticks_ - 1) / window_ticks_ * window_ticks_;
  const std::uint64_t last = window_from_ + window_ticks_ - 1;
  wait([&] { return seen_any_ && last_.tick >= last; }, last);
  RigWindow w;
  w.start_s = window_start_s_;
  w.end_s = clock_s() + 1.0 / options_.rate_Hz;
  w.saturated = last_.saturated_mask != 0;
  if (window_n_ > 0) {
    const double n = static_cast<double>(window_n_);
    Vec3 ifm{};
    for (std::size_t i = 0; i < 3; ++i) {
      w.sgs_um[i] = params_.scaling[i].sgs_to_um(window_sgs_V_[i] / n);
      ifm[i] = window_ifm_um_[i] / n;
    }
    if (window_truth_)
      w.twin_points_um = ifm;
  }
  window_ticks_ = 0;
  return w;
}

std::string LoopRig::fault() const {
  return fault_;
}

}  // namespace piezoshift::rig
