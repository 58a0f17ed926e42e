#pragma once
// Logarithmic creep as a chain of first-order relaxations (a generalized Kelvin-Voigt model),
// linear and cheap, used for the stack's creep and for the strain gauge's own creep.
//
// PI piezo tutorial: after a voltage step, an open-loop stack's displacement creeps as
//   dL(t) = dL(0.1 s) (1 + gamma lg(t / 0.1 s)),   gamma = 0.01 to 0.02 (1 to 2 % per decade).
// The chain: K time constants tau_k spaced n per decade from tau_min to tau_max, each
//   tau_k dc_k/dt = a y - c_k,   a = gamma / n,     output C = sum_k c_k
// so after a step dy the output rises by dy a sum_k (1 - exp(-t / tau_k)), whose slope per decade
// of t is gamma for tau_min << t << tau_max (integral of x e^-x over a log-uniform spread is 1;
// with n = 2 the discrete ripple of the slope is about +-1 %). Beyond tau_max the creep stops, as
// PI's "a few percent after a few hours" says it must.
//
// Discretized exactly for an input held over each update period T (the twin updates the chain
// once per control period with the period's mean input):
//   c_k <- e_k c_k + (1 - e_k) a y,   e_k = exp(-T / tau_k).
//
// Real-time safe (update): no heap, no exceptions, no I/O.
#include <array>
#include <cstddef>
#include <cstdint>

namespace piezoshift::plant {

inline constexpr std::size_t kMaxCreepTerms = 32;

struct CreepParams {
  double per_decade_fraction = 0.015;       //!< gamma (PI tutorial: 0.01 to 0.02)
  double shortest_time_constant_s = 0.01;   //!< tau_min (creep is seen from ~10 ms on)
  double longest_time_constant_s = 1000.0;  //!< tau_max (creep stops after ~hours)
  std::int64_t terms_per_decade = 2;        //!< n

  bool operator==(const CreepParams&) const = default;
};

using CreepState = std::array<double, kMaxCreepTerms>;

class CreepChain {
 public:
  CreepChain() = default;
  //! Throws std::invalid_argument for inconsistent parameters or more than kMaxCreepTerms terms.
  CreepChain(const CreepParams& params, double update_period_s);

  //! One update with the input held (its mean) over the period; returns C = sum c_k.
  double update(CreepState& c, double y) const noexcept {
    double sum = 0.0;
    for (std::size_t k = 0; k < n_; ++k) {
      c[k] = decay_[k] * c[k] + gain_[k] * y;
      sum += c[k];
    }
    return sum;
  }

  //! sum_k c_k without updating.
  double output(const CreepState& c) const noexcept {
    double sum = 0.0;
    for (std::size_t k = 0; k < n_; ++k)
      sum += c[k];
    return sum;
  }

  //! The continuous-time step response factor: C(t) / dy = a sum_k (1 - exp(-t / tau_k)).
  double step_response(double t_s) const noexcept;

  std::size_t terms() const noexcept { return n_; }
  double time_constant_s(std::size_t k) const noexcept { return tau_[k]; }

 private:
  std::size_t n_ = 0;
  double a_ = 0.0;
  std::array<double, kMaxCreepTerms> tau_{};
  std::array<double, kMaxCreepTerms> decay_{};
  std::array<double, kMaxCreepTerms> gain_{};
};

}  // namespace piezoshift::plant
