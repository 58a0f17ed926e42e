#pragma once
// The laboratory's slow thermal drift (paper, Section 4: 22 +- 0.06 degC). The air temperature
// wanders as a band-limited random process (the air conditioning's control error, not a clean
// cycle): a first-order Gauss-Markov (Ornstein-Uhlenbeck) process of rms sigma_a and correlation
// time tau_a. The metrology structure (plate, mechanisms, base, interferometer stand) follows the
// air through a first-order lag of time constant tau_s:
//   T_air = T_0 + x,   x <- e_a x + sigma_a sqrt(1 - e_a^2) N(0, 1),   e_a = exp(-T / tau_a)
//   T_s   = T_0 + y,   y <- y + (1 - e_s) (x - y),                     e_s = exp(-T / tau_s)
// updated once per control period T. The run starts in the stationary distribution:
// var(y) = cov(x, y) = sigma_a^2 tau_a / (tau_a + tau_s), drawn from the seed.
// The interferometer reads a drift
//   d(t) = alpha L (T_s(t) - T_s(0)) + beta L_d (T_air(t) - T_air(0))
// alpha L: the metrology loop's uncompensated steel length times its expansion coefficient
// (45 steel ~11.5e-6 /K); beta L_d: the interferometer's dead path (the air between its optics
// and the measured reflector at the datum, which the XL-80's compensator does not correct: it
// rescales the measured displacement only) times dn/dT (about -0.93e-6 /K near 20 degC, Edlen).
//
// Real-time safe (update): no heap, no exceptions, no I/O.
#include <cmath>

#include "piezoshift/plant/random.hpp"

namespace piezoshift::plant {

struct LabParams {
  double temperature_C = 22.0;  //!< T_0, Section 4
  //! sigma_a: the paper's +-0.06 degC read as +-2 sigma (assumed reading of the tolerance)
  double temperature_rms_K = 0.03;
  //! tau_a: assumed (the ~10 min scale of an air-conditioning control loop)
  double temperature_correlation_time_s = 600.0;
  //! tau_s: thermal time constant of the steel metrology structure in still air, assumed
  double structure_time_constant_s = 1800.0;
  //! L: identified from the paper's repeatability (docs/twin.md, "Repeatability budget"): the
  //! displacement-independent 1.53 nm less the twin's other contributions
  double metrology_loop_length_m = 0.053;
  double metrology_loop_cte_per_K = 11.5e-6;  //!< alpha, steel
  //! L_d: assumed 20 mm (an XL-80 linear kit mounted just above the plate)
  double dead_path_m = 0.02;
  double air_index_per_K = -0.93e-6;  //!< beta = dn/dT of air (Edlen)

  bool operator==(const LabParams&) const = default;
};

struct LabState {
  double air_K = 0.0;        //!< x = T_air - T_0
  double structure_K = 0.0;  //!< y = T_s - T_0
};

class LabEnvironment {
 public:
  LabEnvironment() = default;
  LabEnvironment(const LabParams& p, double update_period_s) noexcept
      : p_(p),
        e_a_(std::exp(-update_period_s / p.temperature_correlation_time_s)),
        drive_(p.temperature_rms_K * std::sqrt(1.0 - e_a_ * e_a_)),
        k_s_(1.0 - std::exp(-update_period_s / p.structure_time_constant_s)) {}

  //! Draws the stationary start (two deviates) and takes it as the datum of the drift.
  void start(LabState& s, Rng& rng) noexcept {
    const double var = p_.temperature_rms_K * p_.temperature_rms_K;
    const double c = var * p_.temperature_correlation_time_s /
                     (p_.temperature_correlation_time_s + p_.structure_time_constant_s);
    s.air_K = p_.temperature_rms_K * rng.normal();
    const double r = var > 0.0 ? c / var : 0.0;
    s.structure_K = r * s.air_K + std::sqrt(std::fmax(0.0, c - c * r)) * rng.normal();
    start_ = s;
  }
  //! One control period (one deviate).
  void update(LabState& s, Rng& rng) const noexcept {
    s.air_K = e_a_ * s.air_K + drive_ * rng.normal();
    s.structure_K += k_s_ * (s.air_K - s.structure_K);
  }

  double air_C(const LabState& s) const noexcept { return p_.temperature_C + s.air_K; }
  double structure_C(const LabState& s) const noexcept { return p_.temperature_C + s.structure_K; }
  //! T_s - T_s(0) [K]
  double structure_change_K(const LabState& s) const noexcept {
    return s.structure_K - start_.structure_K;
  }
  //! d [um]
  double drift_um(const LabState& s) const noexcept {
    return 1e6 * (p_.metrology_loop_cte_per_K * p_.metrology_loop_length_m *
                      (s.structure_K - start_.structure_K) +
                  p_.air_index_per_K * p_.dead_path_m * (s.air_K - start_.air_K));
  }

 private:
  LabParams p_{};
  double e_a_ = 1.0;
  double drive_ = 0.0;
  double k_s_ = 0.0;
  LabState start_{};
};

}  // namespace piezoshift::plant
