#pragma once
// The laboratory's slow thermal drift (paper, Section 4: 22 +- 0.06 degC). The air temperature is
// taken as a sinusoidal cycle of the air conditioning with a stated period; the metrology
// structure (plate, mechanisms, base, interferometer stand) follows it through a first-order lag
// of time constant tau_s, in its periodic steady state:
//   T_air(t) = T_0 + a sin(w t + phi),                     w = 2 pi / P
//   T_s(t)   = T_0 + a G sin(w t + phi - psi),             G = 1 / sqrt(1 + (w tau_s)^2),
//                                                          psi = atan(w tau_s)
// phi, the run's position in the cycle, is drawn once from the twin's seed. The interferometer
// then reads a drift
//   d(t) = alpha L (T_s(t) - T_s(0)) + beta L_air (T_air(t) - T_air(0))
// alpha L: the loop's uncompensated steel length times its expansion coefficient (45 steel
// ~11.5e-6 /K); beta L_air: air path left uncompensated times dn/dT (about -0.93e-6 /K near
// 20 degC, Edlen). The XL-80's environmental compensator (the "compensator kit" of Section 3)
// corrects the air's index from its own sensor, so L_air = 0 by default.
// With the defaults the structure swings +-4.8 mK and the reading +-5.5 nm over a 15 min cycle.
#include <cmath>
#include <numbers>

namespace piezoshift::plant {

struct LabParams {
  double temperature_C = 22.0;            //!< T_0, Section 4
  double temperature_amplitude_K = 0.06;  //!< a, Section 4 (+-0.06 degC)
  double temperature_period_s = 900.0;    //!< P, assumed (air-conditioning cycle)
  //! tau_s: thermal time constant of the steel metrology structure in still air, assumed
  double structure_time_constant_s = 1800.0;
  double metrology_loop_length_m = 0.1;       //!< L, assumed uncompensated steel length
  double metrology_loop_cte_per_K = 11.5e-6;  //!< alpha, steel
  double uncompensated_air_path_m = 0.0;      //!< L_air (compensated by the XL-80, see above)
  double air_index_per_K = -0.93e-6;          //!< beta = dn/dT of air (Edlen)

  bool operator==(const LabParams&) const = default;
};

class LabEnvironment {
 public:
  LabEnvironment() = default;
  LabEnvironment(const LabParams& p, double phase_rad) noexcept
      : p_(p),
        w_(2.0 * std::numbers::pi / p.temperature_period_s),
        phi_(phase_rad),
        gain_(1.0 /
              std::sqrt(1.0 + w_ * p.structure_time_constant_s * w_ * p.structure_time_constant_s)),
        lag_(std::atan(w_ * p.structure_time_constant_s)),
        cos_lag_(std::cos(lag_)),
        sin_lag_(std::sin(lag_)),
        air0_(air_C(0.0)),
        structure0_(structure_C(0.0)) {}

  double air_C(double t_s) const noexcept {
    return p_.temperature_C + p_.temperature_amplitude_K * std::sin(w_ * t_s + phi_);
  }
  double structure_C(double t_s) const noexcept {
    return p_.temperature_C + p_.temperature_amplitude_K * gain_ * std::sin(w_ * t_s + phi_ - lag_);
  }
  //! T_s(t) - T_s(0) [K]
  double structure_change_K(double t_s) const noexcept { return structure_C(t_s) - structure0_; }
  //! d(t) [um]
  double interferometer_drift_um(double t_s) const noexcept {
    return drift_um(air_C(t_s), structure_C(t_s));
  }
  //! d from the two temperatures at the same instant [um].
  double drift_um(double air_C, double structure_C) const noexcept {
    return 1e6 *
           (p_.metrology_loop_cte_per_K * p_.metrology_loop_length_m * (structure_C - structure0_) +
            p_.air_index_per_K * p_.uncompensated_air_path_m * (air_C - air0_));
  }
  double structure_at_start_C() const noexcept { return structure0_; }

  //! The cycle's phase w t + phi [rad] (the twin steps sin and cos of it by rotation).
  double phase_at(double t_s) const noexcept { return w_ * t_s + phi_; }
  double angular_rate_rad_per_s() const noexcept { return w_; }
  //! T_air and T_s from sin and cos of the phase at one instant [degC].
  void temperatures_C(double sin_phase, double cos_phase, double& air_C,
                      double& structure_C) const noexcept {
    air_C = p_.temperature_C + p_.temperature_amplitude_K * sin_phase;
    structure_C = p_.temperature_C + p_.temperature_amplitude_K * gain_ *
                                         (sin_phase * cos_lag_ - cos_phase * sin_lag_);
  }
  double phase_rad() const noexcept { return phi_; }

 private:
  LabParams p_{};
  double w_ = 0.0;
  double phi_ = 0.0;
  double gain_ = 1.0;
  double lag_ = 0.0;
  double cos_lag_ = 1.0;
  double sin_lag_ = 0.0;
  double air0_ = 0.0;
  double structure0_ = 0.0;
};

}  // namespace piezoshift::plant
