#pragma once
// One channel of the piezo power amplifier (paper, Section 4: gain 15, 0-10 V in, 0-150 V out,
// 7 W average power), driving the stack's capacitance C (Table 1: 1.8 uF). Per physics step h,
// with the DAQ voltage v_in held:
//
//   target   = gain v_in
//   dv       = (target - v) (1 - exp(-2 pi f_ss h))     small-signal first-order response, exact
//                                                       for a held input
//   dv       = clamp(dv, -S h, +S h)                    current limit: S = I_max / C
//   v        = clamp(v + dv, output_min_V, output_max_V)   the output rails
//
// I_max is the average-power limit at full voltage, I_max = P_avg / V_max = 7 W / 150 V = 46.7 mA,
// so S = 46.7 mA / 1.8 uF = 25.9 V/ms: a full 0-150 V step slews in about 5.8 ms.
//
// Real-time safe: no heap, no exceptions, no I/O.
#include <algorithm>
#include <cmath>
#include <numbers>

namespace piezoshift::plant {

struct AmplifierParams {
  double gain = 15.0;            //!< [V/V], Section 4
  double output_min_V = 0.0;     //!< Section 4: 0-150 V output
  double output_max_V = 150.0;   //!< Section 4
  double average_power_W = 7.0;  //!< Section 4; sets the current limit P / V_max
  //! Small-signal -3 dB bandwidth into the stack. Not in the paper: an assumed value typical of
  //! linear 150 V piezo amplifiers of this power class into about 2 uF (a few kHz).
  double small_signal_bandwidth_Hz = 3000.0;

  bool operator==(const AmplifierParams&) const = default;
};

//! I_max = P_avg / V_max [A].
inline double amplifier_current_limit_A(const AmplifierParams& p) noexcept {
  return p.average_power_W / p.output_max_V;
}

//! S = I_max / C [V/s].
inline double amplifier_slew_rate_V_per_s(const AmplifierParams& p, double load_capacitance_F) {
  return amplifier_current_limit_A(p) / load_capacitance_F;
}

//! The discretized amplifier of one channel at physics step h (model apart from its state: the
//! state is just the output voltage, kept by the caller).
class Amplifier {
 public:
  Amplifier() = default;
  Amplifier(const AmplifierParams& p, double load_capacitance_F, double step_s) noexcept
      : gain_(p.gain),
        lo_(p.output_min_V),
        hi_(p.output_max_V),
        alpha_(1.0 - std::exp(-2.0 * std::numbers::pi * p.small_signal_bandwidth_Hz * step_s)),
        max_step_V_(amplifier_slew_rate_V_per_s(p, load_capacitance_F) * step_s) {}

  //! One physics step: returns the new output voltage from the old one and the held input.
  double step(double output_V, double input_V) const noexcept {
    const double dv =
        std::min(std::max((gain_ * input_V - output_V) * alpha_, -max_step_V_), max_step_V_);
    return std::max(std::min(output_V + dv, hi_), lo_);
  }

  double max_step_V() const noexcept { return max_step_V_; }

 private:
  double gain_ = 15.0;
  double lo_ = 0.0;
  double hi_ = 150.0;
  double alpha_ = 1.0;
  double max_step_V_ = 0.0;
};

}  // namespace piezoshift::plant
