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
#include <type_traits>

namespace piezoshift::control {

//! Gains per sample (dimensionless when error and output share a unit). Paper, Section 4:
//! kp = 0.6, ki = 0.2, kd = 0.001 at T_s = 1 ms.
template <class T>
struct BasicPidGains {
  T kp = T(0.6);
  T ki = T(0.2);
  T kd = T(0.001);
};

using PidGains = BasicPidGains<double>;

//! Per-sample gains tuned at one sample time, re-expressed for another so that the continuous-time
//! controller they stand for is unchanged: ki scales with T, kd with 1/T, kp stays.
template <class T>
constexpr BasicPidGains<T> rescale_gains(const BasicPidGains<T>& g,
                                         std::type_identity_t<T> from_sample_time_s,
                                         std::type_identity_t<T> to_sample_time_s) noexcept {
  const T r = to_sample_time_s / from_sample_time_s;
  return BasicPidGains<T>{g.kp, g.ki * r, g.kd / r};
}

template <class T>
struct BasicPidParams {
  BasicPidGains<T> gains{};
  T output_min = T(0.0);         //!< lower output limit, in the output's unit
  T output_max = T(16.0);        //!< upper output limit (paper: nominal stroke, 16 um)
  T deadband = T(0.0);           //!< |error| below this counts as zero
  T derivative_filter = T(0.0);  //!< a in d2f = a d2f + (1 - a) d2; 0 = unfiltered
};

using PidParams = BasicPidParams<double>;

template <class T>
struct BasicPidState {
  T error = T(0);    //!< e(k)
  T error_1 = T(0);  //!< e(k-1)
  T error_2 = T(0);  //!< e(k-2)
  T derivative_filtered = T(0);
  T output = T(0);  //!< u(k), after clamping
  bool saturated = false;
  std::uint32_t saturated_count = 0;  //!< consecutive saturated ticks
  std::uint64_t saturated_total = 0;  //!< saturated ticks since reset
};

using PidState = BasicPidState<double>;

template <class T>
class BasicIncrementalPid {
 public:
  constexpr BasicIncrementalPid() noexcept = default;
  constexpr explicit BasicIncrementalPid(const BasicPidParams<T>& params) noexcept
      : params_(params) {}

  //! One controller tick; returns u(k).
  constexpr T update(T command, T feedback) noexcept {
    if (!enabled_) {
      reset(T(0));
      return T(0);
    }
    T e = command - feedback;
    if (!((e < T(0) ? -e : e) > params_.deadband))
      e = T(0);  // also maps a NaN error to 0
    const BasicPidGains<T>& g = params_.gains;
    const T d2 = e - T(2) * state_.error_1 + state_.error_2;
    const T a = params_.derivative_filter;
    state_.derivative_filtered = a * state_.derivative_filtered + (T(1) - a) * d2;
    const T integral = integrator_held_ ? T(0) : g.ki * e;
    const T du = g.kp * (e - state_.error_1) + integral + g.kd * state_.derivative_filtered;
    const T raw = state_.output + du;
    T u = raw;
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
  constexpr void reset(T output = T(0)) noexcept {
    state_ = BasicPidState<T>{};
    state_.output = output;
  }

  //! Disabled: output forced to 0 and state cleared on every update (LinuxCNC pid semantics).
  constexpr void set_enabled(bool enabled) noexcept { enabled_ = enabled; }
  //! Held: the integral term ki e(k) is left out of the increment (used by the safety supervisor).
  constexpr void hold_integrator(bool held) noexcept { integrator_held_ = held; }
  constexpr void set_params(const BasicPidParams<T>& params) noexcept { params_ = params; }

  constexpr bool enabled() const noexcept { return enabled_; }
  constexpr bool integrator_held() const noexcept { return integrator_held_; }
  constexpr const BasicPidParams<T>& params() const noexcept { return params_; }
  constexpr const BasicPidState<T>& state() const noexcept { return state_; }

 private:
  BasicPidParams<T> params_{};
  BasicPidState<T> state_{};
  bool enabled_ = true;
  bool integrator_held_ = false;
};

using IncrementalPid = BasicIncrementalPid<double>;

}  // namespace piezoshift::control
