#include "piezoshift/runtime/safety_supervisor.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "piezoshift/runtime/safety_ranges.hpp"

namespace piezoshift::runtime {

const char* to_string(FaultReason reason) noexcept {
  switch (reason) {
    case FaultReason::kNone:
      return "none";
    case FaultReason::kSgsNotFinite:
      return "sgs-not-finite";
    case FaultReason::kSgsRail:
      return "sgs-rail";
    case FaultReason::kSgsRange:
      return "sgs-range";
    case FaultReason::kSgsJump:
      return "sgs-jump";
    case FaultReason::kTracking:
      return "tracking";
    case FaultReason::kResponse:
      return "response";
    case FaultReason::kOscillation:
      return "oscillation";
    case FaultReason::kSaturation:
      return "saturation";
    case FaultReason::kOverruns:
      return "overruns";
    case FaultReason::kDaqRead:
      return "daq-read";
    case FaultReason::kDaqWrite:
      return "daq-write";
    case FaultReason::kOutputNotFinite:
      return "output-not-finite";
  }
  return "unknown";
}

const char* to_string(SupervisorState state) noexcept {
  switch (state) {
    case SupervisorState::kRunning:
      return "running";
    case SupervisorState::kStopping:
      return "stopping";
    case SupervisorState::kStopped:
      return "stopped";
    case SupervisorState::kFaulted:
      return "faulted";
  }
  return "unknown";
}

namespace {
void demand(bool ok, const char* what) {
  if (!ok)
    throw std::invalid_argument(std::string("SafetyLimits: ") + what);
}
std::uint64_t ticks_for(double seconds, double sample_time_s) {
  return static_cast<std::uint64_t>(std::ceil(seconds / sample_time_s - 1e-9));
}
}  // namespace

bool ReversalCounter::update(std::uint64_t tick, double error, double target, double band,
                             std::uint32_t needed, std::uint64_t window_ticks) noexcept {
  if (!started_) {
    started_ = true;
    extreme_ = error;
    target_at_reversal_ = target;
    return false;
  }
  if (direction_ == 0) {  // the first swing of `band` sets the direction; it is no reversal
    if (std::fabs(error - extreme_) >= band) {
      direction_ = error > extreme_ ? +1 : -1;
      extreme_ = error;
    }
    return false;
  }
  // Follow the extreme in the present direction; a swing of `band` back from it is a reversal.
  bool reversed = false;
  if (direction_ > 0 && error > extreme_) {
    extreme_ = error;
  } else if (direction_ < 0 && error < extreme_) {
    extreme_ = error;
  } else if (std::fabs(error - extreme_) >= band) {
    reversed = true;
    direction_ = error > extreme_ ? +1 : -1;
    extreme_ = error;
  }
  if (!reversed)
    return false;
  // A target that moved is a commanded motion (a step, a wave), not an oscillation: start again.
  if (std::fabs(target - target_at_reversal_) >= band)
    count_ = 0;
  target_at_reversal_ = target;
  ticks_[next_] = tick;
  next_ = (next_ + 1) % kMaxOscillationReversals;
  if (count_ < kMaxOscillationReversals)
    ++count_;
  if (needed < 2 || count_ < needed)
    return false;
  const std::uint32_t oldest =
      (next_ + kMaxOscillationReversals - needed) % kMaxOscillationReversals;
  return tick - ticks_[oldest] <= window_ticks;
}

void SafetySupervisor::configure(
    const SafetyLimits& limits, double sample_time_s,
    const std::array<control::SignalScaling, control::kChannels>& scaling) {
  demand(sample_time_s > 0.0 && std::isfinite(sample_time_s), "sample time must be > 0");
  // The ranges and pairs of safety_ranges.hpp (0 V, the safe state, is inside every output
  // range it accepts).
  if (const std::string problem = safety_limits_problem(limits); !problem.empty())
    throw std::invalid_argument("SafetyLimits: " + problem);
  limits_ = limits;
  sample_time_s_ = sample_time_s;
  scaling_ = scaling;
  for (std::size_t i = 0; i < control::kChannels; ++i) {
    demand(scaling[i].drive_V_per_um > 0.0 && scaling[i].sgs_um_per_V > 0.0, "scaling > 0");
    sgs_per_drive_[i] = limits.stage_gain / (scaling[i].drive_V_per_um * scaling[i].sgs_um_per_V);
  }
  tracking_ticks_ = ticks_for(limits.tracking_time_s, sample_time_s);
  response_ticks_ = ticks_for(limits.response_time_s, sample_time_s);
  saturation_ticks_ = ticks_for(limits.saturation_time_s, sample_time_s);
  oscillation_ticks_ = ticks_for(limits.oscillation_time_s, sample_time_s);
  reset();
}

void SafetySupervisor::reset() noexcept {
  state_ = SupervisorState::kRunning;
  fault_ = FaultRecord{};
  last_ao_V_ = Vec3{};
  have_previous_sgs_ = false;
  consecutive_overruns_ = 0;
  tracking_count_ = {};
  response_count_ = {};
  saturation_count_ = {};
  for (ReversalCounter& r : reversals_)
    r.reset();
}

double SafetySupervisor::jump_limit_V(std::size_t i, double period_s) const noexcept {
  return limits_.sgs_noise_V +
         limits_.jump_factor * limits_.max_slew_V_per_s * period_s * sgs_per_drive_[i];
}

void SafetySupervisor::latch(FaultReason reason, std::uint64_t tick, int channel, double value,
                             double limit) noexcept {
  if (state_ == SupervisorState::kFaulted)
    return;  // the first fault stays latched
  state_ = SupervisorState::kFaulted;
  fault_ = FaultRecord{reason, tick, channel, value, limit};
}

void SafetySupervisor::check(const SupervisorInput& in) noexcept {
  const std::uint64_t k = in.tick;
  if (in.read_status == DaqStatus::kError || in.read_status == DaqStatus::kInactive) {
    latch(FaultReason::kDaqRead, k, -1, static_cast<double>(in.read_status), 0.0);
    return;
  }
  if (in.previous_write_status == DaqStatus::kError ||
      in.previous_write_status == DaqStatus::kInactive) {
    latch(FaultReason::kDaqWrite, k, -1, static_cast<double>(in.previous_write_status), 0.0);
    return;
  }
  consecutive_overruns_ = in.previous_tick_overran ? consecutive_overruns_ + 1 : 0;
  if (limits_.trip_on_overruns != kOverrunTripNever &&
      consecutive_overruns_ >= limits_.max_consecutive_overruns) {
    latch(FaultReason::kOverruns, k, -1, consecutive_overruns_, limits_.max_consecutive_overruns);
    return;
  }

  const double rail = limits_.adc_full_scale_V - limits_.rail_margin_V;
  for (std::size_t i = 0; i < control::kChannels; ++i) {
    const double v = in.sgs_V[i];
    const int ch = static_cast<int>(i);
    if (!std::isfinite(v)) {
      latch(FaultReason::kSgsNotFinite, k, ch, v, 0.0);
      return;
    }
    if (std::fabs(v) >= rail) {
      latch(FaultReason::kSgsRail, k, ch, v, v > 0.0 ? rail : -rail);
      return;
    }
    if (v < limits_.sgs_min_V || v > limits_.sgs_max_V) {
      latch(FaultReason::kSgsRange, k, ch, v,
            v < limits_.sgs_min_V ? limits_.sgs_min_V : limits_.sgs_max_V);
      return;
    }
    if (have_previous_sgs_) {
      const double jump = v - previous_sgs_V_[i];
      const double bound = jump_limit_V(i, in.period_s);
      if (std::fabs(jump) > bound) {
        latch(FaultReason::kSgsJump, k, ch, jump, bound);
        return;
      }
    }
  }
  previous_sgs_V_ = in.sgs_V;
  have_previous_sgs_ = true;

  if (state_ != SupervisorState::kRunning)
    return;  // ramping down on a stop: targets are no longer followed
  for (std::size_t i = 0; i < control::kChannels; ++i) {
    const int ch = static_cast<int>(i);
    const double error = in.target_um[i] - in.feedback_um[i];
    tracking_count_[i] =
        in.closed_loop && std::fabs(error) > limits_.tracking_error_um ? tracking_count_[i] + 1 : 0;
    if (tracking_count_[i] >= tracking_ticks_) {
      latch(FaultReason::kTracking, k, ch, error, limits_.tracking_error_um);
      return;
    }
    const control::SignalScaling& s = scaling_[i];
    const double u_um = s.dac_to_um(last_ao_V_[i]);
    const double lo = limits_.response_gain_min * u_um - limits_.response_band_um;
    const double hi = limits_.response_gain_max * u_um + limits_.response_band_um;
    const double y = in.feedback_um[i];
    const bool outside = y < lo || y > hi;
    response_count_[i] = outside ? response_count_[i] + 1 : 0;
    if (response_count_[i] >= response_ticks_) {
      latch(FaultReason::kResponse, k, ch, y, y < lo ? lo : hi);
      return;
    }
    saturation_count_[i] =
        in.closed_loop && last_ao_V_[i] >= limits_.output_max_V ? saturation_count_[i] + 1 : 0;
    if (saturation_count_[i] >= saturation_ticks_) {
      latch(FaultReason::kSaturation, k, ch, last_ao_V_[i], limits_.output_max_V);
      return;
    }
    if (!in.closed_loop) {
      reversals_[i].reset();
    } else if (reversals_[i].update(k, error, in.target_um[i], limits_.oscillation_band_um,
                                    limits_.oscillation_reversals, oscillation_ticks_)) {
      latch(FaultReason::kOscillation, k, ch, limits_.oscillation_reversals,
            limits_.oscillation_reversals);
      return;
    }
  }
}

SupervisorOutput SafetySupervisor::update(const SupervisorInput& in) noexcept {
  if (state_ == SupervisorState::kRunning) {
    for (std::size_t i = 0; i < control::kChannels; ++i) {
      if (!std::isfinite(in.request_V[i])) {
        latch(FaultReason::kOutputNotFinite, in.tick, static_cast<int>(i), in.request_V[i], 0.0);
        break;
      }
    }
  }
  if (state_ == SupervisorState::kRunning || state_ == SupervisorState::kStopping)
    check(in);

  SupervisorOutput out{};
  const bool running = state_ == SupervisorState::kRunning;
  // A longer period (skipped slots) never buys a larger step.
  const double period_s = in.period_s < sample_time_s_ ? in.period_s : sample_time_s_;
  const double step = (running ? limits_.max_slew_V_per_s : limits_.safe_ramp_V_per_s) * period_s;
  for (std::size_t i = 0; i < control::kChannels; ++i) {
    const double desired = running ? in.request_V[i] : 0.0;
    double v = desired;
    if (v > limits_.output_max_V)
      v = limits_.output_max_V;
    if (v < limits_.output_min_V)
      v = limits_.output_min_V;
    // Within one step the target itself is taken (exactly, not last + delta, which can land an
    // ulp past a limit); otherwise one step towards it, which stays inside [last, v].
    double ao = v;
    if (v - last_ao_V_[i] > step)
      ao = last_ao_V_[i] + step;
    else if (last_ao_V_[i] - v > step)
      ao = last_ao_V_[i] - step;
    out.ao_V[i] = ao;
    out.limited = out.limited || ao != desired;
  }
  last_ao_V_ = out.ao_V;
  if (state_ == SupervisorState::kStopping && outputs_at_zero())
    state_ = SupervisorState::kStopped;
  out.state = state_;
  out.hold_integrators = state_ != SupervisorState::kRunning || out.limited;
  return out;
}

void SafetySupervisor::request_stop() noexcept {
  if (state_ == SupervisorState::kRunning)
    state_ = outputs_at_zero() ? SupervisorState::kStopped : SupervisorState::kStopping;
}

bool SafetySupervisor::clear_fault() noexcept {
  if (state_ != SupervisorState::kFaulted)
    return false;
  state_ = SupervisorState::kRunning;
  fault_ = FaultRecord{};
  have_previous_sgs_ = false;
  consecutive_overruns_ = 0;
  tracking_count_ = {};
  response_count_ = {};
  saturation_count_ = {};
  for (ReversalCounter& r : reversals_)
    r.reset();
  return true;
}

bool SafetySupervisor::outputs_at_zero() const noexcept {
  for (double v : last_ao_V_)
    if (v != 0.0)
      return false;
  return true;
}

}  // namespace piezoshift::runtime
