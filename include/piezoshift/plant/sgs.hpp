#pragma once
// The strain-gauge sensor (SGS) built into each stack and its signal conditioner (paper, Sections
// 2.1 and 4): a bridge bonded to the stack measures the stack's own elongation e_i (not the
// plate's motion), and the conditioner outputs 0..10 V. At each AI sample:
//
//   r_i = g'_i (e_f,i - d_i) + c_T (T_s(t) - T_s(0))     reading in nominal um (what 1.6 um/V
//                                                        turns the volts back into)
//   V_i = o_i + r_i / k_nom + NL FS shape(V_lin / FS) + n,   n ~ N(0, sigma^2)
//
//   e_f     e through the conditioner's first-order low-pass (bandwidth f_c), at the physics rate
//   g'_i    the gauge's reading per um of stack elongation: g_i / (1 + k_m / k_c), so that a
//           closed-loop move reproduces the paper's A (g_i = (A 1)_i, geometry.hpp; the stack
//           elongates (1 + k_m / k_c) um per um of leg motion, contact.hpp)
//   d_i     the gauge's own creep (the bond relaxing under sustained strain): a creep chain
//           (creep.hpp) driven by e; the controller cannot see it, the plate can
//   k_nom   nominal scale, the nominal stroke over full scale: 16 um / 10 V = 1.6 um/V
//   NL FS shape: the conditioner's nonlinearity, 0.1 % of full scale (Section 4), with a stated
//           shape on u = V / FS in [0, 1], each zero at both ends and of peak |1|:
//             bow      4 u (1 - u)                      (a bridge's quadratic nonlinearity)
//             s_curve  10.392 u (1 - u) (1 - 2 u)       (odd, cubic)
//             wave     sin(3 pi u)                      (one a cubic cannot fit)
//   o_i     offset (zero error) of the channel
//   c_T     zero drift with the structure's temperature T_s (lab_environment.hpp)
//   sigma   conditioner noise, white at the sample rate, as nm at the nominal scale
#include <array>
#include <cmath>
#include <cstdint>

namespace piezoshift::plant {

enum class SgsNonlinearityShape : std::uint8_t { kBow, kSCurve, kWave };

struct SgsParams {
  double full_scale_V = 10.0;            //!< conditioner output span 0..10 V (Section 4)
  double nonlinearity_fraction = 0.001;  //!< NL: 0.1 % of full scale (Section 4)
  //! Shape of the nonlinearity. Not in the paper; a bow is the classic bridge nonlinearity.
  SgsNonlinearityShape nonlinearity_shape = SgsNonlinearityShape::kBow;
  //! sigma: rms noise per sample, as nm at the nominal scale (issue: 1 to 2 nm is typical of
  //! SGS-equipped stacks; the paper gives none)
  double noise_nm_rms = 1.5;
  //! f_c: conditioner bandwidth. Not in the paper; assumed 1 kHz (it also serves as the
  //! anti-alias filter for the 1 kHz sampling)
  double bandwidth_Hz = 1000.0;
  //! o_i: zero errors. The conditioners are zeroed at set-up, so 0 by default.
  std::array<double, 3> offset_V{0.0, 0.0, 0.0};
  //! c_T: zero drift per kelvin of the structure. Not in the paper: assumed residual of a full
  //! bridge whose four gauges sit on the same ceramic (their thermal outputs largely cancel).
  double zero_drift_nm_per_K = 5.0;
  //! The gauge's own creep per decade (fraction of the elongation). Not in the paper and no
  //! source for its size on a piezo stack, so off by default; the chain shares the stack's
  //! creep time constants.
  double gauge_creep_per_decade = 0.0;

  bool operator==(const SgsParams&) const = default;
};

//! shape(u) for u clamped to [0, 1]; peak |shape| = 1, zero at both ends.
inline double sgs_nonlinearity_shape(SgsNonlinearityShape s, double u) noexcept {
  u = u < 0.0 ? 0.0 : (u > 1.0 ? 1.0 : u);
  switch (s) {
    case SgsNonlinearityShape::kBow:
      return 4.0 * u * (1.0 - u);
    case SgsNonlinearityShape::kSCurve:
      return 10.392304845413264 * u * (1.0 - u) * (1.0 - 2.0 * u);  // 6 sqrt(3)
    case SgsNonlinearityShape::kWave:
      return std::sin(3.0 * 3.14159265358979323846 * u);
  }
  return 0.0;
}

}  // namespace piezoshift::plant
