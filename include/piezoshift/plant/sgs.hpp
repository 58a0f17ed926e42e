#pragma once
// The strain-gauge sensor (SGS) built into each stack and its signal conditioner (paper, Sections
// 2.1 and 4): a bridge bonded to the stack measures the stack's own elongation e_i (not the
// plate's motion), and the conditioner outputs 0..10 V. At each AI sample:
//
//   r_i = g'_i (1 + delta(t)) (e_f,i - d_i) + c_T (T_s(t) - T_s(0)) + z_i(t)
//                                                        reading in nominal um (what 1.6 um/V
//                                                        turns the volts back into)
//   V_i = o_i + r_i / k_nom + NL FS shape(V_lin / FS) + n,   n ~ N(0, sigma^2)
//
//   e_f     e through the conditioner's first-order low-pass (bandwidth f_c), at the physics rate
//   g'_i    the gauge's reading per um of stack elongation: g_i / (1 + k_m / k_c), so that a
//           closed-loop move reproduces the paper's A (g_i = (A 1)_i, geometry.hpp; the stack
//           elongates (1 + k_m / k_c) um per um of leg motion, contact.hpp)
//   delta   the bridge excitation's relative drift, common to the three channels (one
//           conditioner, one reference): flicker (flicker.hpp), 1/f between 1 s and 10^4 s, its
//           level set by its rms over a window (below). A bridge's output is proportional to its
//           excitation, so this error grows with the displacement.
//   d_i     the gauge's own creep (the bond relaxing under sustained strain): a creep chain
//           (creep.hpp, the stack's time constants) driven by e, scaled so that a step of e
//           creeps by gauge_creep_fraction after gauge_creep_time_s; the controller cannot see
//           it, the plate can
//   z_i     the conditioner's zero flicker, per channel: 1/f between 0.01 s and 10^4 s with
//           its corner (1/f PSD = white PSD) at flicker_corner_Hz
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
  //! The gauge's own creep: the fraction of a step of strain it loses (relaxation) within
  //! gauge_creep_time_s. Not in the paper; gauge makers bound the creep of matched gauges at
  //! about 0.02 % of full scale over 20 min (HBM, Vishay "creep-matched" transducer gauges), used
  //! here at that bound.
  double gauge_creep_fraction = 0.0002;
  double gauge_creep_time_s = 1200.0;  //!< the 20 min of that specification
  //! Corner of the conditioner's zero flicker, where its 1/f PSD meets the white noise's. Not in
  //! the paper; assumed 1 Hz, typical of the instrumentation amplifiers of DC bridge
  //! conditioners (their 0.1 to 10 Hz noise about equals their white noise in that band).
  double flicker_corner_Hz = 1.0;
  //! delta's rms over a window of excitation_drift_window_s. Identified from the paper's
  //! repeatability (Section 4.3): a displacement-independent part a and a gain part b with
  //! sqrt(a^2 + (5 b)^2) = 2 nm and sqrt(a^2 + (10 b)^2) = 3 nm give b = 0.258 nm/um (258 ppm)
  //! and a = 1.53 nm.
  double excitation_drift_ppm_rms = 258.0;
  //! The window of that rms: the duration of the 230-move repeatability run (the twin's
  //! schedule, docs/experiments.md: 230 moves of 3 s).
  double excitation_drift_window_s = 690.0;

  bool operator==(const SgsParams&) const = default;
};

//! shape(u) for u clamped to [0, 1]; peak |shape| = 1, zero at both ends.
// The flicker bands (flicker.hpp), one term per decade: the zero flicker from 10 ms (above that
// the white noise dominates) to about 3 h; the excitation drift from 1 s (faster fluctuations
// average out in a 1 s reading) to about 3 h.
inline constexpr double kSgsZeroFlickerShortestS = 0.01;
inline constexpr double kSgsExcitationShortestS = 1.0;
inline constexpr double kSgsFlickerLongestS = 1.0e4;

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
