#include "piezoshift/runtime/control_loop.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace piezoshift::runtime {

const char* to_string(StopReason reason) noexcept {
  switch (reason) {
    case StopReason::kDuration:
      return "duration";
    case StopReason::kSignal:
      return "signal";
    case StopReason::kFault:
      return "fault";
  }
  return "unknown";
}

namespace {

// The loop's period as the controller's sample time (its gains are rescaled from
// gains_sample_time_s).
std::int64_t period_ns_of(const LoopConfig& config) {
  if (!(config.rate_Hz > 0.0) || !std::isfinite(config.rate_Hz))
    throw std::invalid_argument("ControlLoop: rate_Hz must be > 0");
  return std::llround(1e9 / config.rate_Hz);
}

control::SemiClosedLoopParams at_loop_period(control::SemiClosedLoopParams params,
                                             const LoopConfig& config) {
  params.sample_time_s = static_cast<double>(period_ns_of(config)) * 1e-9;
  return params;
}

}  // namespace

ControlLoop::ControlLoop(const LoopConfig& config, const control::SemiClosedLoopParams& params,
                         const SafetyLimits& limits, DaqBackend& daq, LoopClock& clock,
                         SetpointProfile profile, SpscRing<TelemetryRecord>* telemetry)
    : config_(config),
      params_(at_loop_period(params, config)),
      period_ns_(period_ns_of(config)),
      duration_ticks_(0),
      daq_(daq),
      clock_(clock),
      profile_(std::move(profile)),
      telemetry_(telemetry),
      cycle_(params_, limits) {
  if (!(config.duration_s >= 0.0) || std::isnan(config.duration_s))
    throw std::invalid_argument("ControlLoop: duration_s must be >= 0");
  const double ticks = config.duration_s * config.rate_Hz;
  duration_ticks_ = ticks >= 1.8e19 ? std::numeric_limits<std::uint64_t>::max()
                                    : static_cast<std::uint64_t>(std::llround(ticks));
}

LoopResult ControlLoop::run() noexcept {
  start();
  while (tick()) {
  }
  return result_;
}

void ControlLoop::start() noexcept {
  result_ = LoopResult{};
  result_.min_output_V = std::numeric_limits<double>::infinity();
  result_.max_output_V = -std::numeric_limits<double>::infinity();
  cycle_.reset();
  profile_.rewind();
  stats_.clear();
  tick_ = 0;
  start_ns_ = clock_.now_ns();
  deadline_ns_ = start_ns_;
  previous_deadline_ns_ = start_ns_ - period_ns_;
  previous_wake_ns_ = start_ns_;
  previous_overran_ = false;
  overrun_worst_late_ns_ = 0;
  was_faulted_ = false;
  recorded_fault_tick_ = 0;
  if (config_.status != nullptr)
    config_.status->faults_published.store(0, std::memory_order_release);
  stop_requested_ = false;
  finish_requested_ = false;
  done_ = false;
  previous_ao_V_ = Vec3{};
  // Host and owner modes: servo off at 0 V until told otherwise. The profile is followed from the
  // first tick.
  host_zd_um_ = Vec3{};
  wave_ = WaveGenerator{};
  applied_sequence_ = 0;
  configure_problem_ = control::ParamsProblem::kNone;
  if (trigger_high_)  // a pulse cut short by the previous run's end
    daq_.stage_trigger_line(false);
  trigger_armed_ = trigger_high_ = false;
  trigger_ticks_left_ = 0;
  trigger_pulses_ = 0;
  trigger_edge_ = TriggerEdge{};
  if (config_.host == nullptr && !config_.owner_drives)
    cycle_.drive_points(profile_.at(0.0));
}

bool ControlLoop::tick() noexcept {
  if (done_)
    return false;
  clock_.sleep_until_ns(deadline_ns_);
  const std::int64_t wake = clock_.now_ns();
  const CycleTime ct{tick_, deadline_ns_ - start_ns_, deadline_ns_ - previous_deadline_ns_};

  check_stop();
  if (clear_requested_.exchange(false, std::memory_order_acq_rel))
    clear_latched_fault();
  apply_host_commands();
  choose_setpoint(ct);
  if (trigger_armed_ || trigger_high_) [[unlikely]]
    drive_trigger_line(ct);

  const CycleSample& cs = cycle_.step(daq_, ct, previous_overran_);
  const Vec3& zd = cs.zd_um;  // zero unless on Z_d: S is no Z_d
  record_outputs(cs, zd);
  publish_status(cs, zd, ct);

  const std::int64_t end = clock_.now_ns();
  previous_overran_ = stats_.record(deadline_ns_, wake, end, previous_wake_ns_, period_ns_);
  overrun_worst_late_ns_ =
      previous_overran_ ? std::max(overrun_worst_late_ns_, end - deadline_ns_ - period_ns_) : 0;
  push_telemetry(cs, zd, ct, wake, end);
  push_host_sample(cs, zd, ct, wake);

  ++tick_;
  if (done(cs))
    return false;
  previous_wake_ns_ = wake;
  next_deadline(end);
  return true;
}

void ControlLoop::check_stop() noexcept {
  if (stop_requested_)
    return;
  if (tick_ >= duration_ticks_ || finish_requested_) {
    stop_requested_ = true;
    result_.stop_reason = StopReason::kDuration;
  } else if (config_.stop_signal != nullptr &&
             config_.stop_signal->load(std::memory_order_relaxed) != 0) {
    stop_requested_ = true;
    result_.stop_reason = StopReason::kSignal;
    result_.signal = config_.stop_signal->load(std::memory_order_relaxed);
  }
  if (stop_requested_)
    cycle_.request_stop();
}

void ControlLoop::clear_latched_fault() noexcept {
  if (cycle_.clear_fault() && stop_requested_)
    cycle_.request_stop();
}

void ControlLoop::apply_host_commands() noexcept {
  HostLink* const host = config_.host;
  HostCommand cmd{};
  for (int n = 0;
       host != nullptr && n < HostLink::kMaxCommandsPerTick && host->commands.try_pop(cmd); ++n) {
    applied_sequence_ = cmd.sequence;
    ++result_.host_commands_applied;
    apply(cmd);
  }
}

void ControlLoop::apply(const HostCommand& cmd) noexcept {
  const bool closed_loop = cycle_.mode() != DriveMode::kOpenLoop;
  switch (cmd.kind) {
    case HostCommand::Kind::kMoveTo:
      if (closed_loop)
        host_zd_um_ = cmd.zd_um;
      break;
    case HostCommand::Kind::kServoOn:
      clear_latched_fault();
      // Bumpless: each PID resumes from the command the output already holds.
      host_zd_um_ = cmd.zd_um;
      cycle_.drive_points(host_zd_um_);
      cycle_.restart_from_outputs();
      break;
    case HostCommand::Kind::kServoOff:
      clear_latched_fault();
      cycle_.drive_open_loop(cycle_.supervisor().last_output_V());
      break;
    case HostCommand::Kind::kOpenLoop:
      if (!closed_loop)
        cycle_.drive_open_loop(cmd.ao_V);
      break;
    case HostCommand::Kind::kWave:
      wave_.apply(cmd.wave, host_zd_um_);
      break;
    case HostCommand::Kind::kActuators:
      cycle_.drive_actuators(cmd.actuator_target_um);
      break;
    case HostCommand::Kind::kConfigure: {
      // Checked here, refused without a change and reported in the samples: never thrown.
      control::SemiClosedLoopParams p{};
      configure_problem_ = config_.host->params.try_pop(p) ? cycle_.try_configure(p)
                                                           : control::ParamsProblem::kAbsent;
      break;
    }
  }
}

void ControlLoop::choose_setpoint(const CycleTime& t) noexcept {
  if (config_.host != nullptr) {
    // The host's set-point plus its running wave generators (stopped unless the servo is on
    // Z_d and no fault is latched).
    const bool points = cycle_.mode() == DriveMode::kPoints;
    const Vec3 zd = wave_.next(host_zd_um_, points && !cycle_.supervisor().faulted());
    if (points)
      cycle_.drive_points(zd);
  } else if (!config_.owner_drives) {
    cycle_.drive_points(profile_.at(static_cast<double>(t.since_start_ns) * 1e-9));
  }
}

bool ControlLoop::arm_trigger_pulse(std::uint32_t width_ticks) noexcept {
  if (trigger_armed_ || trigger_high_ || width_ticks == 0 || width_ticks > kMaxTriggerPulseTicks ||
      !daq_.has_trigger_line())
    return false;
  trigger_armed_ = true;
  trigger_width_ticks_ = width_ticks;
  return true;
}

// Staged before the tick's read(): the level goes out in this tick's transaction.
void ControlLoop::drive_trigger_line(const CycleTime& t) noexcept {
  if (trigger_armed_) {
    trigger_armed_ = false;
    trigger_high_ = true;
    trigger_ticks_left_ = trigger_width_ticks_;
    trigger_edge_ = TriggerEdge{t.tick, t.since_start_ns};
    ++trigger_pulses_;
    daq_.stage_trigger_line(true);
  }
  if (trigger_ticks_left_ == 0) {
    trigger_high_ = false;
    daq_.stage_trigger_line(false);
    return;
  }
  --trigger_ticks_left_;
}

void ControlLoop::record_outputs(const CycleSample& cs, const Vec3& zd) noexcept {
  const SafetySupervisor& supervisor = cycle_.supervisor();
  if (supervisor.faulted() && !result_.fault_detected) {
    result_.fault_detected = true;
    result_.fault = supervisor.fault();
  }
  record_fault();
  const double period_ms = params_.sample_time_s * 1e3;
  const Vec3& ao = cs.supervisor.ao_V;
  for (std::size_t i = 0; i < ao.size(); ++i) {
    result_.max_output_V = std::max(result_.max_output_V, ao[i]);
    result_.min_output_V = std::min(result_.min_output_V, ao[i]);
    result_.max_output_slew_V_per_ms = std::max(result_.max_output_slew_V_per_ms,
                                                std::fabs(ao[i] - previous_ao_V_[i]) / period_ms);
  }
  previous_ao_V_ = ao;
  result_.last_sgs_V = cs.ai_V;
  if (!stop_requested_ && cs.mode != DriveMode::kOpenLoop && !supervisor.faulted()) {
    const control::ControllerOutput& c = cs.controller;
    result_.controlled_end_tick = tick_ + 1;
    result_.end_zd_um = zd;
    result_.end_target_um = c.target_um;
    result_.end_feedback_um = c.feedback_um;
    Vec3 truth{};
    if (!daq_.truth(truth, result_.end_interferometer_um)) {
      const double nan = std::numeric_limits<double>::quiet_NaN();
      result_.end_interferometer_um = Vec3{nan, nan, nan};
    }
  }
}

// A latch is new when the previous tick had none, or when its tick differs from the last one
// recorded (a clear at the start of this tick and a new latch in it). It was latched in this
// tick's step: its time is this tick's.
void ControlLoop::record_fault() noexcept {
  const SafetySupervisor& supervisor = cycle_.supervisor();
  const bool faulted = supervisor.faulted();
  const bool fresh = faulted && (!was_faulted_ || supervisor.fault().tick != recorded_fault_tick_);
  was_faulted_ = faulted;
  if (!fresh)
    return;
  LatchedFault f{};
  f.fault = supervisor.fault();
  recorded_fault_tick_ = f.fault.tick;
  f.t_s = static_cast<double>(deadline_ns_ - start_ns_) * 1e-9;
  // The supervisor saw the overruns of the ticks before this one: the run still in the stats.
  if (f.fault.reason == FaultReason::kOverruns)
    f.worst_lateness_s = static_cast<double>(overrun_worst_late_ns_) * 1e-9;
  const std::uint32_t index = result_.faults.count;
  result_.faults.append(f);
  if (config_.status != nullptr) {
    if (index < kMaxFaultsKept)
      config_.status->faults[index] = f;
    config_.status->faults_published.store(index + 1, std::memory_order_release);
  }
}

void ControlLoop::publish_status(const CycleSample& cs, const Vec3& zd,
                                 const CycleTime& t) noexcept {
  if (config_.status == nullptr)
    return;
  const SafetySupervisor& supervisor = cycle_.supervisor();
  LoopStatus& st = *config_.status;
  st.t_s.store(static_cast<double>(t.since_start_ns) * 1e-9, std::memory_order_relaxed);
  st.publish_vec(st.zd_um, zd);
  st.publish_vec(st.target_um, cs.controller.target_um);
  st.publish_vec(st.feedback_um, cs.controller.feedback_um);
  st.state.store(static_cast<std::uint8_t>(cs.supervisor.state), std::memory_order_relaxed);
  st.fault_reason.store(static_cast<std::uint8_t>(supervisor.fault().reason),
                        std::memory_order_relaxed);
  st.ticks.store(tick_ + 1, std::memory_order_relaxed);
}

void ControlLoop::push_telemetry(const CycleSample& cs, const Vec3& zd, const CycleTime& t,
                                 std::int64_t wake_ns, std::int64_t end_ns) noexcept {
  if (telemetry_ == nullptr)
    return;
  const SafetySupervisor& supervisor = cycle_.supervisor();
  const SupervisorOutput& s = cs.supervisor;
  TelemetryRecord r{};
  r.tick = tick_;
  r.t_s = static_cast<double>(t.since_start_ns) * 1e-9;
  r.zd_um = zd;
  r.target_um = cs.controller.target_um;
  r.sgs_V = cs.ai_V;
  r.request_V = cs.controller.dac_V;
  r.ao_V = s.ao_V;
  if (!daq_.truth(r.truth_um, r.interferometer_um)) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    r.truth_um = Vec3{nan, nan, nan};
    r.interferometer_um = r.truth_um;
  }
  r.wake_latency_us = static_cast<double>(wake_ns - deadline_ns_) * 1e-3;
  r.compute_us = static_cast<double>(end_ns - wake_ns) * 1e-3;
  r.overrun = previous_overran_ ? 1 : 0;
  r.limited = s.limited ? 1 : 0;
  r.held = s.hold_integrators ? 1 : 0;
  r.state = static_cast<std::uint8_t>(s.state);
  r.fault_reason = static_cast<std::uint8_t>(supervisor.fault().reason);
  r.fault_channel = static_cast<std::int8_t>(supervisor.fault().channel);
  r.read_status = static_cast<std::uint8_t>(cs.read_status);
  r.write_status = static_cast<std::uint8_t>(cs.write_status);
  if (!telemetry_->try_push(r))
    ++result_.telemetry_dropped;
}

void ControlLoop::push_host_sample(const CycleSample& cs, const Vec3& zd, const CycleTime& t,
                                   std::int64_t wake_ns) noexcept {
  HostLink* const host = config_.host;
  if (host == nullptr)
    return;
  const SafetySupervisor& supervisor = cycle_.supervisor();
  const bool closed_loop = cs.mode != DriveMode::kOpenLoop;
  HostSample h{};
  h.tick = tick_;
  h.t_s = static_cast<double>(t.since_start_ns) * 1e-9;
  h.applied_sequence = applied_sequence_;
  h.configure_problem = static_cast<std::uint8_t>(configure_problem_);
  h.zd_um = zd;
  h.target_um = cs.controller.target_um;
  h.sgs_V = cs.ai_V;
  h.ao_V = cs.supervisor.ao_V;
  h.has_truth = daq_.truth(h.truth_um, h.interferometer_um) ? 1 : 0;
  h.fringe_drift_nm = daq_.fringe_drift_nm();
  h.wake_latency_us = static_cast<double>(wake_ns - deadline_ns_) * 1e-3;
  h.overrun = previous_overran_ ? 1 : 0;
  h.closed_loop = closed_loop && !supervisor.faulted() ? 1 : 0;
  h.actuators = cs.mode == DriveMode::kActuators ? 1 : 0;
  h.saturated_mask = closed_loop ? cs.controller.saturated_mask : 0;
  h.state = static_cast<std::uint8_t>(cs.supervisor.state);
  h.fault_reason = static_cast<std::uint8_t>(supervisor.fault().reason);
  h.fault_channel = static_cast<std::int8_t>(supervisor.fault().channel);
  h.wave_running = wave_.running_mask();
  if (!host->samples.try_push(h))
    ++result_.host_samples_dropped;
}

bool ControlLoop::done(const CycleSample& cs) noexcept {
  const SafetySupervisor& supervisor = cycle_.supervisor();
  const bool safe_after_fault = supervisor.faulted() && supervisor.outputs_at_zero();
  done_ = cs.supervisor.state == SupervisorState::kStopped ||
          (safe_after_fault && (config_.stop_when_safe_after_fault || stop_requested_));
  if (done_) {
    result_.ticks = tick_;
    if (safe_after_fault)
      result_.stop_reason = StopReason::kFault;
    if (supervisor.faulted())
      result_.fault = supervisor.fault();
  }
  return done_;
}

void ControlLoop::next_deadline(std::int64_t end_ns) noexcept {
  previous_deadline_ns_ = deadline_ns_;
  deadline_ns_ += period_ns_;
  if (end_ns > deadline_ns_) {  // missed the next deadline: re-phase to the first slot after E_k
    const std::int64_t skip = (end_ns - deadline_ns_ + period_ns_ - 1) / period_ns_;
    deadline_ns_ += skip * period_ns_;
    stats_.skipped_slots += static_cast<std::uint64_t>(skip);
  }
}

}  // namespace piezoshift::runtime
