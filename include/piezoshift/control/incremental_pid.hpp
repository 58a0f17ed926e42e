#pragma once
// Incremental (velocity-form) discrete PID, the inner loop of the paper (Section 3, Eqs. 6 and 7).
//
// Per tick, with gains given per sample as the paper gives them:
//   if !enabled:           u = 0, state cleared, return
//   e      = command - feedback
//   if |e| <= deadband:    e = 0
//   d2     = e - 2 e1 + e2                          second difference (derivative term of Eq. 7)
//   d2f    = a d2f + (1 - a) d2                     optional first-order filter, a in [0, 1)
//   du     = kp (e - e1) + ki e + kd d2f            Eq. 7 (ki e dropped while integrator held)
//   u_raw  = u1 + du                                Eq. 6
//   u      = clamp(u_raw, output_min, output_max)   the clamped u is what is carried forward,
//                                                   so a saturated loop never winds up
//   saturated = (u != u_raw); saturated_count counts consecutive saturated ticks
//   e2 = e1; e1 = e; u1 = u
//
// Real-time safe: no heap, no exceptions, no I/O; every member is noexcept.
#include <cstdint>

namespace piezoshift::control {

//! Gains per sample (dimensionless when error and output share a unit). Paper, Section 4:
//! kp = 0.6, ki = 0.2, kd = 0.001 at T_s = 1 ms.
struct PidGains {
  double kp = 0.6;
  double ki = 0.2;
  double kd = 0.001;
};

//! Per-sample gains tuned at one sample time, re-expressed for another so that the continuous-time
//! controller they stand for is unchanged: ki scales with T, kd with 1/T, kp stays.
constexpr PidGains rescale_gains(const PidGains& g, double from_sample_time_s,
                                 double to_sample_time_s) noexcept {
  const double r = to_sample_time_s / from_sample_time_s;
  return PidGains{g.kp, g.ki * r, g.kd / r};
}

struct PidParams {
  PidGains gains{};
  double output_min = 0.0;         //!< lower output limit, in the output's unit
  double output_max = 16.0;        //!< upper output limit (paper: nominal stroke, 16 um)
  double deadband = 0.0;           //!< |error| below this counts as zero
  double derivative_filter = 0.0;  //!< a in d2f = a d2f + (1 - a) d2; 0 = unfiltered
};

struct PidState {
  double error = 0.0;    //!< e(k)
  double error_1 = 0.0;  //!< e(k-1)
  double error_2 = 0.0;  //!< e(k-2)
  double derivative_filtered = 0.0;
  double output = 0.0;  //!< u(k), after clamping
  bool saturated = false;
  std::uint32_t saturated_count = 0;  //!< consecutive saturated ticks
  std::uint64_t saturated_total = 0;  //!< saturated ticks since reset
};

class IncrementalPid {
 public:
  constexpr IncrementalPid() noexcept = default;
  constexpr explicit IncrementalPid(const PidParams& params) noexcept : params_(params) {}

  //! One controller tick; returns u(k).
  constexpr double update(double command, double feedback) noexcept {
    if (!enabled_) {
      reset(0.0);
      return 0.0;
    }
    double e = command - feedback;
    if (!((e < 0.0 ? -e : e) > params_.deadband))
      e = 0.0;  // also maps a NaN error to 0
    const PidGains& g = params_.gains;
    const double d2 = e - 2.0 * state_.error_1 + state_.error_2;
    const double a = params_.derivative_filter;
    state_.derivative_filtered = a * state_.derivative_filtered + (1.0 - a) * d2;
    const double integral = integrator_held_ ? 0.0 : g.ki * e;
    const double du = g.kp * (e - state_.error_1) + integral + g.kd * state_.derivative_filtered;
    const double raw = state_.output + du;
    double u = raw;
    if (u > params_.output_max)
      u = params_.output_max;
    if (u < params_.output_min)
      u = params_.output_min;
    if (!(u == u))
      u = state_.output;  // a NaN increment never reaches the output
    state_.saturated = (u != raw);
    if (state_.saturated) {
      ++state_.saturated_count;
      ++state_.saturated_total;
    } else {
      state_.saturated_count = 0;
    }
    state_.error_2 = state_.error_1;
    state_.error_1 = e;
    state_.error = e;
    state_.output = u;
    return u;
  }

  //! Clears the error history and counters and sets u(k-1) (bumpless start from a known output).
  constexpr void reset(double output = 0.0) noexcept {
    state_ = PidState{};
    state_.output = output;
  }

  //! Disabled: output forced to 0 and state cleared on every update (LinuxCNC pid semantics).
  constexpr void set_enabled(bool enabled) noexcept { enabled_ = enabled; }
  //! Held: the integral term ki e(k) is left out of the increment (used by the safety supervisor).
  constexpr void hold_integrator(bool held) noexcept { integrator_held_ = held; }
  constexpr void set_params(const PidParams& params) noexcept { params_ = params; }

  constexpr bool enabled() const noexcept { return enabled_; }
  constexpr bool integrator_held() const noexcept { return integrator_held_; }
  constexpr const PidParams& params() const noexcept { return params_; }
  constexpr const PidState& state() const noexcept { return state_; }

 private:
  PidParams params_{};
  PidState state_{};
  bool enabled_ = true;
  bool integrator_held_ = false;
};

}  // namespace piezoshift::control
