#pragma once
// The improved controller's model of one actuator channel, from its command u (um of command,
// signal_scaling.hpp) to its strain gauge's reading y (SGS um): a Prandtl-Ishlinskii hysteresis
// (weighted play operators) followed by a logarithmic creep, the standard compensator structure of
// piezo stages (Kuhnen and Janocha's inverse PI; PI's creep law dL(t) = dL(0.1 s)(1 + g lg(t/0.1))
// realised as first-order terms spread evenly over the decades):
//
//   s_j <- clamp(s_j, u - r_j, u)                  play operator j, threshold r_j (um of command)
//   h    = w0 u + sum_j w_j s_j                    rate-independent hysteresis
//   c_m <- a_m c_m + (1 - a_m) h,  a_m = e^{-T/tau_m}   creep terms, unit gain each
//   y    = offset + h + creep_gain sum_m (c_m - h)  creep: y rises after a step as the c_m follow h
//
// Written with (c_m - h) the creep adds nothing in a steady state reached long ago; it appears in
// the first tau_m after a move and takes a slope per decade of time set by creep_gain. Every
// parameter is linear in y once the operators and the creep terms are run on the command, so the
// calibration identifies the model by least squares (calibration/hysteresis_identification.hpp).
//
// inverse() finds the u that makes the model read a target now: h is piecewise linear and
// monotone in u from the present operator states (upwards the operators with s_j + r_j below u are
// dragged, downwards those with s_j above u), so the inverse is exact, by walking the breakpoints.
// It needs non-negative weights (the identification keeps them so).
//
// Real-time safe: no heap, no exceptions, no I/O; fixed sizes; every member noexcept.
#include <array>
#include <cmath>
#include <cstddef>

namespace piezoshift::control {

inline constexpr std::size_t kMaxModelOperators = 16;
inline constexpr std::size_t kMaxCreepTerms = 12;

template <class T>
struct BasicHysteresisCreepParams {
  T offset_um = T(0);
  T linear_weight = T(1);                                   //!< w0 (SGS um per um of command)
  std::size_t operators = 0;                                //!< play operators in use
  std::array<T, kMaxModelOperators> threshold_um{};         //!< r_j, increasing
  std::array<T, kMaxModelOperators> weight{};               //!< w_j >= 0
  std::size_t creep_terms = 0;                              //!< creep terms in use
  std::array<T, kMaxCreepTerms> creep_time_constant_s{};    //!< tau_m
  T creep_gain = T(0);                                      //!< per term (the fit's coefficient)
};

using HysteresisCreepParams = BasicHysteresisCreepParams<double>;

template <class To, class From>
constexpr BasicHysteresisCreepParams<To> convert(const BasicHysteresisCreepParams<From>& p) noexcept {
  BasicHysteresisCreepParams<To> q{};
  q.offset_um = static_cast<To>(p.offset_um);
  q.linear_weight = static_cast<To>(p.linear_weight);
  q.operators = p.operators;
  for (std::size_t j = 0; j < kMaxModelOperators; ++j) {
    q.threshold_um[j] = static_cast<To>(p.threshold_um[j]);
    q.weight[j] = static_cast<To>(p.weight[j]);
  }
  q.creep_terms = p.creep_terms;
  for (std::size_t m = 0; m < kMaxCreepTerms; ++m)
    q.creep_time_constant_s[m] = static_cast<To>(p.creep_time_constant_s[m]);
  q.creep_gain = static_cast<To>(p.creep_gain);
  return q;
}

template <class T>
class BasicHysteresisCreepModel {
 public:
  using Params = BasicHysteresisCreepParams<T>;

  constexpr BasicHysteresisCreepModel() noexcept = default;

  //! Sets the parameters for a sample time; the state restarts at rest at u = 0.
  constexpr void configure(const Params& params, T sample_time_s) noexcept {
    p_ = params;
    if (p_.operators > kMaxModelOperators)
      p_.operators = kMaxModelOperators;
    if (p_.creep_terms > kMaxCreepTerms)
      p_.creep_terms = kMaxCreepTerms;
    for (std::size_t m = 0; m < p_.creep_terms; ++m)
      alpha_[m] = std::exp(-sample_time_s / p_.creep_time_constant_s[m]);
    reset_to(T(0));
  }

  //! The state after a slow monotone approach from 0 to u, settled (a bumpless start where the
  //! history is not known: the operators as a rising branch leaves them, the creep run out).
  constexpr void reset_to(T u) noexcept {
    u_ = u;
    for (std::size_t j = 0; j < p_.operators; ++j) {
      const T lo = u - p_.threshold_um[j];
      s_[j] = lo > T(0) ? lo : T(0);
    }
    h_ = hysteresis(s_, u);
    for (std::size_t m = 0; m < p_.creep_terms; ++m)
      c_[m] = h_;
  }

  //! The model's reading now (after the last commit).
  constexpr T output() const noexcept { return p_.offset_um + h_ + creep(); }

  //! The command that makes the model read y now (exact; ends of [u_min, u_max] when out of reach,
  //! with clamped set).
  constexpr T inverse(T y, T u_min, T u_max, bool& clamped) const noexcept {
    // After commit(u) the creep terms hold a_m c_m + (1 - a_m) h(u), so the reading is
    // offset + h (1 - g sum a_m) + g sum a_m c_m: solved for h exactly.
    T sum_a = T(0);
    T sum_ac = T(0);
    for (std::size_t m = 0; m < p_.creep_terms; ++m) {
      sum_a += alpha_[m];
      sum_ac += alpha_[m] * c_[m];
    }
    const T h_target =
        (y - p_.offset_um - p_.creep_gain * sum_ac) / (T(1) - p_.creep_gain * sum_a);
    T u = invert_hysteresis(h_target);
    clamped = false;
    if (!(u == u))
      u = u_;
    if (u > u_max) {
      u = u_max;
      clamped = true;
    }
    if (u < u_min) {
      u = u_min;
      clamped = true;
    }
    return u;
  }

  //! The command applied this tick: the operators move, the creep terms advance one tick.
  constexpr void commit(T u) noexcept {
    for (std::size_t j = 0; j < p_.operators; ++j) {
      T s = s_[j];
      const T lo = u - p_.threshold_um[j];
      s = s < lo ? lo : s;
      s = s > u ? u : s;
      s_[j] = s;
    }
    u_ = u;
    h_ = hysteresis(s_, u);
    for (std::size_t m = 0; m < p_.creep_terms; ++m)
      c_[m] = alpha_[m] * c_[m] + (T(1) - alpha_[m]) * h_;
  }

  //! Local slope dy/du for a small move up (rising) or down from the present state.
  constexpr T slope(bool rising) const noexcept {
    T g = p_.linear_weight;
    for (std::size_t j = 0; j < p_.operators; ++j) {
      const bool dragged = rising ? !(s_[j] + p_.threshold_um[j] > u_) : !(s_[j] < u_);
      if (dragged)
        g += p_.weight[j];
    }
    return g;
  }

  constexpr T command_um() const noexcept { return u_; }
  constexpr const Params& params() const noexcept { return p_; }

 private:
  constexpr T creep() const noexcept {
    T sum = T(0);
    for (std::size_t m = 0; m < p_.creep_terms; ++m)
      sum += c_[m] - h_;
    return p_.creep_gain * sum;
  }

  constexpr T hysteresis(const std::array<T, kMaxModelOperators>& s, T u) const noexcept {
    T h = p_.linear_weight * u;
    for (std::size_t j = 0; j < p_.operators; ++j)
      h += p_.weight[j] * s[j];
    return h;
  }

  // h(u) from the present states is continuous, piecewise linear and non-decreasing; walk its
  // breakpoints from u_ towards the target.
  constexpr T invert_hysteresis(T h_target) const noexcept {
    std::array<T, kMaxModelOperators> bp{};  // where each operator not yet moving starts to
    std::array<T, kMaxModelOperators> bw{};  // and its weight
    std::size_t n = 0;
    const bool up = h_target >= h_;
    // Upwards operator j starts to move at u = s_j + r_j; downwards at u = s_j.
    for (std::size_t j = 0; j < p_.operators; ++j) {
      const T b = up ? s_[j] + p_.threshold_um[j] : s_[j];
      if (up ? b > u_ : b < u_) {
        bp[n] = b;
        bw[n] = p_.weight[j];
        ++n;
      }
    }
    // Insertion sort (n <= 16): ascending upwards, descending downwards.
    for (std::size_t i = 1; i < n; ++i) {
      const T v = bp[i];
      const T w = bw[i];
      std::size_t k = i;
      while (k > 0 && (up ? bp[k - 1] > v : bp[k - 1] < v)) {
        bp[k] = bp[k - 1];
        bw[k] = bw[k - 1];
        --k;
      }
      bp[k] = v;
      bw[k] = w;
    }
    T slope = this->slope(up);
    T u = u_;
    T h = h_;
    for (std::size_t i = 0; i <= n; ++i) {
      if (!(slope > T(0)))
        return u;  // a flat model cannot reach further (weights are non-negative, w0 > 0)
      const T u_next = u + (h_target - h) / slope;
      if (i == n || (up ? u_next <= bp[i] : u_next >= bp[i]))
        return u_next;
      h += slope * (bp[i] - u);
      u = bp[i];
      slope += bw[i];  // past its breakpoint this operator moves with the input
    }
    return u;
  }

  Params p_{};
  std::array<T, kMaxModelOperators> s_{};
  std::array<T, kMaxCreepTerms> c_{};
  std::array<T, kMaxCreepTerms> alpha_{};
  T u_ = T(0);
  T h_ = T(0);
};

using HysteresisCreepModel = BasicHysteresisCreepModel<double>;

}  // namespace piezoshift::control
