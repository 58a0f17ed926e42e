#pragma once
// The external laser interferometer, a Renishaw XL-80 class system (paper, Sections 3 and 4):
// a 633 nm He-Ne laser, 1 nm resolution, 0.5 ppm system accuracy. The twin reads the three
// measurement points P1..P3 (the paper moves one linear kit between them; the twin has all three
// at once). Displacements are relative to the datum set when the twin starts.
//
//   z_j(t)     true displacement of P_j (rigid plate, geometry.hpp)
//   m_j        = (1 + eps) z_j + d(t) + c sin(4 pi z_j / lambda) + n,   n ~ N(0, sigma^2)
//   eps        the run's scale error, drawn once per run uniformly in +-accuracy (the 0.5 ppm)
//   d(t)       metrology-loop drift of the lab (lab_environment.hpp)
//   c          periodic (cyclic) nonlinearity, period lambda / 2 of displacement (one fringe of a
//              retroreflector pair); 0 by default, the paper gives none
//   dynamic    one sample every 1 / f_dyn (Section 4.1: 1 kHz), rounded to the resolution
//   static     the mean of the quantized samples of each averaging window (Section 4.2: 1 s),
//              rounded to the resolution again, published at the end of its window: the
//              XL-80 counts whole resolution steps, so it averages counts, not the analogue
//              position (without noise, a position 0.45 nm for 60 % of a window and 0.9 nm for
//              40 % reads 0 nm; averaging first would read 1 nm)
#include <cmath>
#include <cstdint>

namespace piezoshift::plant {

struct InterferometerParams {
  double wavelength_nm = 633.0;  //!< He-Ne (Section 3); sets the period of the cyclic error
  double resolution_nm = 1.0;    //!< XL-80 (Section 4)
  double accuracy_ppm = 0.5;     //!< XL-80 system accuracy (Section 4)
  //! sigma per dynamic sample. Not in the paper: assumed 1 nm rms (electronics and air
  //! turbulence over a short beam path in a closed, temperature-controlled lab)
  double noise_nm_rms = 1.0;
  double cyclic_error_nm = 0.0;            //!< c, amplitude of the periodic nonlinearity
  double dynamic_sample_rate_Hz = 1000.0;  //!< Section 4.1 (Figure 10: 1 kHz)
  double static_average_s = 1.0;           //!< Section 4.2: 1 s sampling interval

  bool operator==(const InterferometerParams&) const = default;
};

//! One reading quantized to the resolution (both in the same unit).
inline double interferometer_quantize(double value, double resolution) noexcept {
  return std::nearbyint(value / resolution) * resolution;
}

//! The static mode's reading from the sum of n quantized samples.
inline double interferometer_static_reading(double quantized_sum, double n,
                                            double resolution) noexcept {
  return interferometer_quantize(quantized_sum / n, resolution);
}

}  // namespace piezoshift::plant
