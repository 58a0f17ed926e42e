#include "piezoshift/runtime/control_loop.hpp"

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
  LoopResult result{};
  cycle_.reset();
  profile_.rewind();
  stats_.clear();
  const double period_s = params_.sample_time_s;
  const double period_ms = period_s * 1e3;
  result.min_output_V = std::numeric_limits<double>::infinity();
  result.max_output_V = -std::numeric_limits<double>::infinity();

  const std::int64_t start = clock_.now_ns();
  std::int64_t deadline = start;
  std::int64_t previous_deadline = start - period_ns_;
  std::int64_t previous_wake = start;
  bool previous_overran = false;
  bool stop_requested = false;
  Vec3 previous_ao{};

  // Host mode state: servo off at 0 V until the host says otherwise. Without a host the loop
  // follows the profile from the first tick.
  HostLink* const host = config_.host;
  if (host == nullptr)
    cycle_.drive(DriveMode::kPoints, profile_.at(0.0));
  Vec3 host_zd{};
  WaveGenerator wave;  // fixed-size; the tables are the host's (wave_generator.hpp)
  std::uint64_t applied_sequence = 0;
  control::ParamsProblem configure_problem = control::ParamsProblem::kNone;
  const auto clear_latched_fault = [&]() noexcept {
    if (cycle_.clear_fault() && stop_requested)
      cycle_.request_stop();
  };
  const SafetySupervisor& supervisor = cycle_.supervisor();

  for (std::uint64_t tick = 0;; ++tick) {
    clock_.sleep_until_ns(deadline);
    const std::int64_t wake = clock_.now_ns();
    const CycleTime ct{tick, deadline - start, deadline - previous_deadline};

    if (!stop_requested) {
      if (tick >= duration_ticks_) {
        stop_requested = true;
        result.stop_reason = StopReason::kDuration;
      } else if (config_.stop_signal != nullptr &&
                 config_.stop_signal->load(std::memory_order_relaxed) != 0) {
        stop_requested = true;
        result.stop_reason = StopReason::kSignal;
        result.signal = config_.stop_signal->load(std::memory_order_relaxed);
      }
      if (stop_requested)
        cycle_.request_stop();
    }
    if (clear_requested_.exchange(false, std::memory_order_acq_rel))
      clear_latched_fault();

    HostCommand cmd{};
    for (int n = 0;
         host != nullptr && n < HostLink::kMaxCommandsPerTick && host->commands.try_pop(cmd); ++n) {
      applied_sequence = cmd.sequence;
      ++result.host_commands_applied;
      const bool closed_loop = cycle_.mode() != DriveMode::kOpenLoop;
      switch (cmd.kind) {
        case HostCommand::Kind::kMoveTo:
          if (closed_loop)
            host_zd = cmd.zd_um;
          break;
        case HostCommand::Kind::kServoOn:
          clear_latched_fault();
          // Bumpless: each PID resumes from the command the output already holds.
          host_zd = cmd.zd_um;
          cycle_.drive(DriveMode::kPoints, host_zd);
          cycle_.restart_from_outputs();
          break;
        case HostCommand::Kind::kServoOff:
          clear_latched_fault();
          cycle_.drive(DriveMode::kOpenLoop, supervisor.last_output_V());
          break;
        case HostCommand::Kind::kOpenLoop:
          if (!closed_loop)
            cycle_.drive(DriveMode::kOpenLoop, cmd.ao_V);
          break;
        case HostCommand::Kind::kWave:
          wave.apply(cmd.wave, host_zd);
          break;
        case HostCommand::Kind::kActuators:
          cycle_.drive(DriveMode::kActuators, cmd.zd_um);
          break;
        case HostCommand::Kind::kConfigure: {
          // Checked here, refused without a change and reported in the samples: never thrown.
          control::SemiClosedLoopParams p{};
          configure_problem =
              host->params.try_pop(p) ? cycle_.try_configure(p) : control::ParamsProblem::kAbsent;
          break;
        }
      }
    }
    if (host == nullptr) {
      cycle_.drive(DriveMode::kPoints, profile_.at(static_cast<double>(ct.since_start_ns) * 1e-9));
    } else {
      // The host's set-point plus its running wave generators (stopped unless the servo is on
      // Z_d and no fault is latched).
      const bool points = cycle_.mode() == DriveMode::kPoints;
      const Vec3 zd = wave.next(host_zd, points && !supervisor.faulted());
      if (points)
        cycle_.drive(DriveMode::kPoints, zd);
    }

    const CycleSample& cs = cycle_.step(daq_, ct, previous_overran);
    const SupervisorOutput& s = cs.supervisor;
    const control::ControllerOutput& c = cs.controller;
    const bool closed_loop = cs.mode != DriveMode::kOpenLoop;
    const Vec3 zd = cs.mode == DriveMode::kPoints ? cs.setpoint : Vec3{};  // S is no Z_d
    if (supervisor.faulted() && !result.fault_detected) {
      result.fault_detected = true;
      result.fault = supervisor.fault();
    }

    for (std::size_t i = 0; i < s.ao_V.size(); ++i) {
      const double v = s.ao_V[i];
      if (v > result.max_output_V)
        result.max_output_V = v;
      if (v < result.min_output_V)
        result.min_output_V = v;
      const double slew = std::fabs(v - previous_ao[i]) / period_ms;
      if (slew > result.max_output_slew_V_per_ms)
        result.max_output_slew_V_per_ms = slew;
    }
    previous_ao = s.ao_V;
    result.last_sgs_V = cs.ai_V;
    if (config_.status != nullptr) {
      LoopStatus& st = *config_.status;
      st.t_s.store(static_cast<double>(ct.since_start_ns) * 1e-9, std::memory_order_relaxed);
      st.publish_vec(st.zd_um, zd);
      st.publish_vec(st.target_um, c.target_um);
      st.publish_vec(st.feedback_um, c.feedback_um);
      st.state.store(static_cast<std::uint8_t>(s.state), std::memory_order_relaxed);
      st.fault_reason.store(static_cast<std::uint8_t>(supervisor.fault().reason),
                            std::memory_order_relaxed);
      st.ticks.store(tick + 1, std::memory_order_relaxed);
    }
    if (!stop_requested && closed_loop && !supervisor.faulted()) {
      result.controlled_end_tick = tick + 1;
      result.end_zd_um = zd;
      result.end_target_um = c.target_um;
      result.end_feedback_um = c.feedback_um;
      Vec3 truth{};
      if (!daq_.truth(truth, result.end_interferometer_um)) {
        const double nan = std::numeric_limits<double>::quiet_NaN();
        result.end_interferometer_um = Vec3{nan, nan, nan};
      }
    }

    const std::int64_t end = clock_.now_ns();
    previous_overran = stats_.record(deadline, wake, end, previous_wake, period_ns_);

    if (telemetry_ != nullptr) {
      TelemetryRecord r{};
      r.tick = tick;
      r.t_s = static_cast<double>(ct.since_start_ns) * 1e-9;
      r.zd_um = zd;
      r.target_um = c.target_um;
      r.sgs_V = cs.ai_V;
      r.request_V = c.dac_V;
      r.ao_V = s.ao_V;
      if (!daq_.truth(r.truth_um, r.interferometer_um)) {
        const double nan = std::numeric_limits<double>::quiet_NaN();
        r.truth_um = Vec3{nan, nan, nan};
        r.interferometer_um = r.truth_um;
      }
      r.wake_latency_us = static_cast<double>(wake - deadline) * 1e-3;
      r.compute_us = static_cast<double>(end - wake) * 1e-3;
      r.overrun = previous_overran ? 1 : 0;
      r.limited = s.limited ? 1 : 0;
      r.held = s.hold_integrators ? 1 : 0;
      r.state = static_cast<std::uint8_t>(s.state);
      r.fault_reason = static_cast<std::uint8_t>(supervisor.fault().reason);
      r.fault_channel = static_cast<std::int8_t>(supervisor.fault().channel);
      r.read_status = static_cast<std::uint8_t>(cs.read_status);
      r.write_status = static_cast<std::uint8_t>(cs.write_status);
      if (!telemetry_->try_push(r))
        ++result.telemetry_dropped;
    }

    if (host != nullptr) {
      HostSample h{};
      h.tick = tick;
      h.t_s = static_cast<double>(ct.since_start_ns) * 1e-9;
      h.applied_sequence = applied_sequence;
      h.configure_problem = static_cast<std::uint8_t>(configure_problem);
      h.zd_um = zd;
      h.target_um = c.target_um;
      h.sgs_V = cs.ai_V;
      h.ao_V = s.ao_V;
      h.has_truth = daq_.truth(h.truth_um, h.interferometer_um) ? 1 : 0;
      h.wake_latency_us = static_cast<double>(wake - deadline) * 1e-3;
      h.overrun = previous_overran ? 1 : 0;
      h.closed_loop = closed_loop && !supervisor.faulted() ? 1 : 0;
      h.actuators = cs.mode == DriveMode::kActuators ? 1 : 0;
      h.saturated_mask = closed_loop ? c.saturated_mask : 0;
      h.state = static_cast<std::uint8_t>(s.state);
      h.fault_reason = static_cast<std::uint8_t>(supervisor.fault().reason);
      h.fault_channel = static_cast<std::int8_t>(supervisor.fault().channel);
      h.wave_running = wave.running_mask();
      if (!host->samples.try_push(h))
        ++result.host_samples_dropped;
    }

    const bool safe_after_fault = supervisor.faulted() && supervisor.outputs_at_zero();
    if (s.state == SupervisorState::kStopped ||
        (safe_after_fault && (config_.stop_when_safe_after_fault || stop_requested))) {
      result.ticks = tick + 1;
      if (safe_after_fault)
        result.stop_reason = StopReason::kFault;
      break;
    }

    previous_wake = wake;
    previous_deadline = deadline;
    deadline += period_ns_;
    if (end > deadline) {  // missed the next deadline: re-phase to the first slot after `end`
      const std::int64_t skip = (end - deadline + period_ns_ - 1) / period_ns_;
      deadline += skip * period_ns_;
      stats_.skipped_slots += static_cast<std::uint64_t>(skip);
    }
  }
  if (supervisor.faulted())
    result.fault = supervisor.fault();
  return result;
}

}  // namespace piezoshift::runtime
