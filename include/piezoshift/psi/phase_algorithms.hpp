#pragma once
// Wrapped phase from a set of phase-shifted frames.
//
// Frames: I_k(x) = A(x) + B(x) cos(phi(x) + delta_k),  delta_0 = 0, a positive step increases the
// phase; in a Fizeau in reflection phi = 4 pi h / lambda (docs/psi.md).
//
// Weighted sums (4-step, Hariharan/Schwider 5-frame, de Groot 7-frame, the 13-frame pi/4, and
// least squares with known steps): with complex coefficients c_k = d_k + i n_k,
//   S = sum_k c_k I_k,   phi = arg(S) - arg(H(+1)),
//   H(+-1) = sum_k c_k exp(+-i delta_k),   sum_k c_k = 0   (Freischlad and Koliopoulos 1990,
//   JOSA A 7(4):542: the characteristic-polynomial description).
// So S = (B/2) [exp(i phi) H(+1) + exp(-i phi) H(-1)]: an algorithm measures phi exactly when
// H(-1) = 0 at the actual steps, and its error under wrong steps is arg(1 + r exp(-2 i phi)) with
// r = H(-1)/H(+1), a peak-to-valley of 2 asin|r| (phase_error_pv_rad()).
//   4-step (Wyant 1975):          n = (0, -1, 0, 1),  d = (1, 0, -1, 0),  steps pi/2
//   Hariharan/Schwider 5-frame (Hariharan, Oreb and Eiju 1987, Appl. Opt. 26(13):2504;
//   Schwider et al. 1983):        n = (0, -2, 0, 2, 0),  d = (1, 0, -2, 0, 1),  steps pi/2
//     under a step of pi/2 (1 + eps): tan(psi') = tan(psi) / cos(pi eps / 2), psi = phi + pi
//   de Groot 7-frame (de Groot 1995, Appl. Opt. 34(22):4723):
//                                 n = (-1, 0, 7, 0, -7, 0, 1),  d = (0, -4, 0, 8, 0, -4, 0):
//                                 the literature's (-I1 + 7 I3 - 7 I5 + I7) / (-4 I2 + 8 I4 - 4 I6)
//                                 with 1-based frames, phase at the centre frame; steps pi/2
//   13-frame pi/4: a Hann-windowed DFT over 13 frames at pi/4 (de Groot's data-sampling-window
//     construction), projected so that it rejects the background and the conjugate term exactly
//     and the conjugate term to first order in a linear step error. Built here, not copied from
//     a publication: its coefficients are printed by `piezoshift psi analyze --json`.
//   Least squares with known steps (Greivenkamp 1984, Opt. Eng. 23(4):350): per pixel
//     [1, cos delta_k, -sin delta_k] [A, B cos phi, B sin phi]^T = I_k, whose pseudo-inverse
//     rows are the weights.
//
// Carre (1966; Creath 1988): four frames at -3a, -a, a, 3a (unknown a, nominal pi/4), not a
// weighted sum:
//   P = 3 (I1 - I2) - (I0 - I3),  Q = (I0 - I3) + (I1 - I2),  tan^2 a = P / Q,
//   tan psi = sign(I1 - I2) sqrt(|P Q|) / ((I1 + I2) - (I0 + I3)),
// psi being the phase at the centre of the sequence, immune to any constant step. We return
// psi - 3 a_median (a piston, removed with the surface's piston) and steps k * 2 a_median.
//
// Advanced iterative algorithm, AIA (Wang and Han 2004, Opt. Lett. 29(14):1671), unknown steps:
//   (1) steps known: per pixel least squares for (A, B cos phi, B sin phi);
//   (2) phase known: per frame least squares over the pupil for (a_k, b_k cos d_k, b_k sin d_k),
//       assuming background and modulation uniform within a frame;
// alternated until the steps change by less than tolerance_rad. The result is referred to frame 0
// (delta_0 = 0) and to a positive mean step (phi -> -phi, delta -> -delta is the same data).
// Where the phase spans too little of a fringe over the pupil the alternation crawls and stops
// at steps far from the truth (on the twin: 30 nm RMS of coma, 0.30 rad off, settled), so the
// result is refused below min_step_conditioning (PhaseResult::step_conditioning): about a third
// of a fringe of defocus or coma over the pupil, or half a fringe of tilt.
//
// Tilt-aware AIA: as AIA with each frame's shift a plane over the pupil,
//   delta_k(x, y) = piston_k + tip_k y + tilt_k x   (x, y pupil coordinates, grid.hpp),
// the tripod's three degrees of freedom; step (2) becomes a Gauss-Newton fit of
// (a_k, b_k, piston_k, tip_k, tilt_k) per frame (in the spirit of Xu et al. 2008, Opt. Lett.
// 33(4):405, for tilt-shift errors). For the plate of geometry.hpp, tip_k = (4 pi / lambda)
// theta_x R and tilt_k = -(4 pi / lambda) theta_y R at pupil radius R.
// It runs from three starts (plain AIA's steps; a grid of planes, solved linearly for piston,
// against AIA's phase and against the least-squares phase at the commanded steps) and keeps the
// one that settles with the smallest residual.
//
// Both AIAs check their own result (docs/psi.md, "Fits that check themselves"): settled, steps
// within step_tolerance_rad of the commanded ones, for aia a phase spread enough to determine
// them (min_step_conditioning), planes within max_tilt_rad, and the frames' residual from the
// model at their noise; otherwise converged = false with the reason.
#include <complex>
#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "piezoshift/psi/grid.hpp"

namespace piezoshift::psi {

enum class Algorithm : std::uint8_t {
  kFourStep,
  kCarre,
  kHariharan5,
  kDeGroot7,
  kFrame13,
  kLeastSquares,
  kAia,
  kTiltAia,
};

//! 4step, carre, hariharan5, degroot7, frame13, lsq, aia, tilt-aia
std::string_view algorithm_name(Algorithm a);
//! Throws core::InputError naming the value and the valid names.
Algorithm parse_algorithm(std::string_view name);
std::vector<Algorithm> all_algorithms();
//! Frames the algorithm needs: its fixed count, or 0 when any count >= 3 works.
int required_frames(Algorithm a);
//! The nominal step between frames [rad]: pi/2 except the 13-frame's pi/4.
double nominal_step_rad(Algorithm a);

struct WeightedSum {
  std::vector<std::complex<double>> c;  //!< c_k = d_k + i n_k
  std::vector<double> steps_rad;        //!< the delta_k it was designed for
  double reference_rad = 0.0;           //!< arg H(+1), subtracted so that delta_0 = 0
};

//! The fixed weighted sums (4-step, hariharan5, degroot7, frame13); std::invalid_argument else.
WeightedSum weighted_sum(Algorithm a);
//! Least squares with known steps (at least 3, not all equal modulo 2 pi).
WeightedSum least_squares_sum(std::span<const double> steps_rad);
//! H(s) = sum_k c_k exp(i s delta_k) at the given actual steps.
std::complex<double> characteristic(const WeightedSum& w, std::span<const double> steps_rad,
                                    double s);
//! Peak-to-valley phase error of w when the frames are taken at steps_rad: 2 asin|H(-1)/H(+1)|
//! (the background rejected, i.e. sum c_k = 0).
double phase_error_pv_rad(const WeightedSum& w, std::span<const double> steps_rad);

struct PhaseOptions {
  Algorithm algorithm = Algorithm::kHariharan5;
  //! Known steps delta_k [rad] for lsq (empty: k pi/2); initial guess for aia and tilt-aia.
  std::vector<double> steps_rad;
  int max_iterations = 200;      //!< aia, tilt-aia
  double tolerance_rad = 1e-6;   //!< aia, tilt-aia: stop when no step changes more
  double min_modulation = 1e-9;  //!< pixels with a smaller B estimate are left NaN
  // aia, tilt-aia check their own fit (docs/psi.md, "Fits that check themselves"):
  //! a recovered step further than this from the commanded one (steps_rad, else k pi/2, both
  //! referred to frame 0) is a wrong solution: twice the +-0.25 rad the fits are shown to reach
  double step_tolerance_rad = 0.5;
  //! tilt-aia: a shift plane (relative to frame 0's) steeper than this at the pupil edge [rad]
  //! is outside the range the starts cover (each frame's tilt up to 1 rad there, so 2 between two)
  double max_tilt_rad = 2.5;
  //! the frames' residual from the fitted model, beyond its white noise, as a fraction of the
  //! median modulation: more is a wrong basin or frames the model does not describe
  double max_misfit = 0.02;
  //! aia: the least PhaseResult::step_conditioning that determines the steps. On the twin's
  //! frames (docs/psi.md) every surface at 0.0341 or less gave steps 0.3 to 0.6 rad off, most
  //! of them reported settled, and every one at 0.0351 or more within 8 mrad: 0.05 leaves a margin
  double min_step_conditioning = 0.05;
};

//! One frame's phase shift over the pupil: piston + tip y + tilt x [rad] (tilt-aware methods).
struct FrameShift {
  double piston_rad = 0.0;
  double tip_rad = 0.0;
  double tilt_rad = 0.0;
};

//! The per-frame shifts as three columns (the JSON and Python outputs' piston_rad, tip_rad,
//! tilt_rad).
struct FrameShiftColumns {
  std::vector<double> piston_rad, tip_rad, tilt_rad;
};
FrameShiftColumns shift_columns(const std::vector<FrameShift>& shifts);

struct PhaseResult {
  Map phase_rad;                   //!< wrapped to (-pi, pi], NaN outside the mask
  Map modulation;                  //!< B estimate (frame units), NaN outside the mask
  std::vector<double> steps_rad;   //!< delta_k used or recovered (piston at the pupil centre)
  std::vector<FrameShift> shifts;  //!< tilt-aia only
  int iterations = 0;              //!< aia, tilt-aia
  //! aia: the smallest eigenvalue of (1/N) sum_x u u^T, u = (1, cos phi, sin phi) over the pupil
  //! (the per-pixel normal matrix of AIA's step (2)): 0.5 for a phase spread evenly over a fringe
  //! or more, 0 for a flat phase, which says nothing about the steps; NaN for the others
  double step_conditioning = std::numeric_limits<double>::quiet_NaN();
  //! aia, tilt-aia: the iteration settled AND the fit passed its checks (steps near the
  //! commanded ones, planes within range, residual at the noise); the other algorithms: true
  bool converged = true;
  std::string reason;  //!< why not converged, "" when converged
  //! aia, tilt-aia: RMS of the frames' residual from the fitted model, and its white part (from
  //! adjacent-pixel differences), each over the pupil's median modulation; NaN for the others
  double residual_rms = std::numeric_limits<double>::quiet_NaN();
  double noise_rms = std::numeric_limits<double>::quiet_NaN();
};

//! Wrapped phase from frames (same size as the mask, at least 3). Throws std::invalid_argument
//! for a wrong frame count or sizes (callers that read files check first and name the file).
PhaseResult wrapped_phase(std::span<const Map> frames, const Mask& mask,
                          const PhaseOptions& options);

}  // namespace piezoshift::psi
