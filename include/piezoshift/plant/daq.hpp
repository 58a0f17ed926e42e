#pragma once
// The data-acquisition board, NI PCI-6229 (paper, Section 4): 16-bit DAC and ADC over +-10 V,
// analog outputs held (zero-order hold) for one control period, analog inputs sampled once per
// period with the board's input noise.
//
//   LSB      q = 2 range / 2^bits                                (0.305 mV for 16 bit, +-10 V)
//   code     c = clamp(round(v / q), -2^(bits-1), 2^(bits-1) - 1)   (the converter saturates)
//   value    v_q = c q
//   AO       v_out = v_q(v_cmd), held from the write until the next write
//   AI       v_in  = v_q(v_signal + n),  n ~ N(0, ai_noise_V_rms^2) drawn once per sample
//
// Real-time safe: no heap, no exceptions, no I/O.
#include <cmath>
#include <cstdint>

namespace piezoshift::plant {

struct DaqParams {
  //! T_s: AO update and AI sample period, the paper's control period (Section 4: 1 ms)
  double sample_time_s = 1e-3;
  double range_V = 10.0;              //!< +-range of AO and AI (PCI-6229, Section 4: +-10 V)
  std::int64_t resolution_bits = 16;  //!< ADC and DAC resolution (PCI-6229, Section 4: 16 bit)
  //! AI random noise, rms, on the +-10 V range. NI M Series specifications (NI 6259, the 6229's
  //! sibling with the same 16-bit converter family): 280 uV rms on +-10 V.
  double ai_noise_V_rms = 280e-6;

  bool operator==(const DaqParams&) const = default;
};

//! One least significant bit [V].
inline double daq_lsb_V(const DaqParams& p) noexcept {
  return 2.0 * p.range_V / std::ldexp(1.0, static_cast<int>(p.resolution_bits));
}

//! The converter's code for a voltage, saturated at the end codes; NaN gives code 0.
inline std::int64_t daq_code(const DaqParams& p, double v) noexcept {
  const double half = std::ldexp(1.0, static_cast<int>(p.resolution_bits) - 1);
  const double c = std::nearbyint(v / daq_lsb_V(p));
  if (!(c == c))
    return 0;
  if (c < -half)
    return static_cast<std::int64_t>(-half);
  if (c > half - 1.0)
    return static_cast<std::int64_t>(half - 1.0);
  return static_cast<std::int64_t>(c);
}

//! The voltage a code stands for.
inline double daq_quantize_V(const DaqParams& p, double v) noexcept {
  return static_cast<double>(daq_code(p, v)) * daq_lsb_V(p);
}

}  // namespace piezoshift::plant
