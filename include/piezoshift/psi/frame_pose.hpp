#pragma once
// The reference plate's pose from ONE frame, against a reference taken once with a phase-shifting
// set: what the fringe lock (control/fringe_lock.hpp) reads at the camera's frame rate, where a
// whole phase-shifting set per correction would divide the rate by its frame count.
//
// Reference (frame_pose_reference): from a set of frames at steps 0, pi/2, ... (hariharan5's five,
// or any set wrapped_phase() takes with known pi/2 steps), per pupil pixel the bias a, the
// modulation b and the phase phi of the frames' model I_k = a + b cos(phi + delta_k); a is the
// mean of four consecutive frames (pi/2 apart, their cosines cancel).
//
// A frame is then fitted, over the pupil, by the model of the Fizeau (fizeau_simulation.hpp):
//   I(x, y) = a + k b cos(phi + (4 pi / lambda) d(x, y)),
//   d = Z + theta_x y_m - theta_y x_m          (y_m = y R_pupil: the plate's rigid-body motion)
// for (k, Z, theta_x, theta_y): k the fringes' contrast against the reference's, d the plate's
// motion since the reference. Gauss-Newton from a start (the last frame's pose: the caller
// tracks), which converges to the solution within a quarter wave of the start: the piston's
// fringe order is the start's, so consecutive frames must differ by less than lambda / 8 of
// piston at every pupil point (about 80 nm; FramePoseOptions::max_step_nm refuses more).
// The fit checks itself (a failure is a result with valid = false and the reason, never a pose):
//   k < min_contrast              the fringes are gone (a blocked beam, a stopped camera's dark
//                                 frame, the test piece moved out)
//   not settled in max_iterations
//   misfit > max_misfit           RMS residual over k median(b): not the surface the reference
//                                 saw, or a pose beyond the start's basin
//   |d - start| > max_step_nm     at the pupil's edge: a step the fringe order cannot follow
// What it assumes: the test surface and the illumination are the reference's (a changed surface
// is a misfit), the plate moves rigidly, and the camera's pupil is the mask's.
#include <span>
#include <string>

#include "piezoshift/psi/grid.hpp"

namespace piezoshift::psi {

struct FramePoseReference {
  Map bias;        //!< a [counts]
  Map modulation;  //!< b [counts]
  Map phase_rad;   //!< phi, wrapped
  Mask mask;
  Pupil pupil;
  double median_modulation = 0.0;
};

//! frames: at least four at steps 0, pi/2, pi, 3 pi/2 (more: the first five as hariharan5). Throws
//! std::invalid_argument for fewer frames or sizes other than the mask's.
FramePoseReference frame_pose_reference(std::span<const Map> frames, const Mask& mask);

struct FramePoseOptions {
  double wavelength_nm = 632.8;
  double pupil_radius_m = 0.025;  //!< the pupil on the plate (FizeauParams::pupil_radius_m)
  int max_iterations = 20;
  double tolerance_nm = 1e-4;  //!< settled: no point of the pupil moved more in the last step
  //! The least contrast k taken as fringes: assumed 0.3 (a third of the reference's; a camera's
  //! noise is about 1 % of b on the twin, so well above it)
  double min_contrast = 0.3;
  //! The largest RMS residual over k median(b): assumed 0.1 (the twin's frames fit to about
  //! 0.02, its shot and read noise and the 12-bit quantisation; tests/psi/frame_pose_test.cpp)
  double max_misfit = 0.1;
  //! The largest motion from the start at any pupil point: lambda / 8 (the basin's edge is a
  //! quarter wave of phase; half of it leaves the noise a margin)
  double max_step_nm = 79.1;
};

//! The plate's pose relative to the reference.
struct FramePose {
  double piston_nm = 0.0;
  double theta_x_urad = 0.0;
  double theta_y_urad = 0.0;
  double contrast = 0.0;  //!< k
  double misfit = 0.0;    //!< RMS residual / (k median b)
  int iterations = 0;
  bool valid = false;
  std::string reason;  //!< why not valid, "" when valid
};

//! Fits frame from start (the previous pose; {} right after the reference). The frame must be the
//! reference's size (std::invalid_argument otherwise).
FramePose fit_frame_pose(const Map& frame, const FramePoseReference& reference,
                         const FramePose& start, const FramePoseOptions& options = {});

}  // namespace piezoshift::psi
