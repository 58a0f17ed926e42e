#pragma once
// The stacked piezo actuator with built-in strain-gauge sensor (paper, Section 2.1, Table 1).

namespace piezoshift::design {

struct ActuatorParams {
  double stiffness_N_per_um = 70.0;  //!< k_a, Table 1
  double nominal_stroke_um = 16.0;   //!< x_a, nominal travel range, Section 2.1 (150 V, Sec. 4.1)
  double pushing_force_N = 1400.0;   //!< Table 1
  double pulling_force_N = 150.0;    //!< Table 1
  double capacitance_F = 1.8e-6;     //!< Table 1: 1.8 uF
  double resonance_frequency_Hz = 30000.0;  //!< Table 1: natural frequency 30 kHz
  double length_m = 0.028;                  //!< Table 1: 28 mm

  bool operator==(const ActuatorParams&) const = default;
};

}  // namespace piezoshift::design
