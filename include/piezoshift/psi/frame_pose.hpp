#pragma once
// One frame's phase plane against a known reference phase, and with it the reference plate's
// pose from ONE frame: what the fringe lock (control/fringe_lock.hpp) reads at the camera's frame
// rate, where a whole phase-shifting set per correction would divide the rate by its frame count,
// and what the fringe tracker (fringe_tracker.hpp) fits each frame after its first window with.
//
// fit_phase_plane(): over the reference's pixels q, the frame is fitted by
//   I_q = alpha A_q + beta B_q cos(phi_q + piston + tip y_q + tilt x_q)
// with A_q = B_q = 1 when the reference has no per-pixel bias and modulation (alpha, beta are then
// the frame's own, as tilt-aware AIA's step (2) takes them uniform), else A_q = a_q and B_q = b_q
// (alpha about 1, beta the fringes' contrast against the reference's). First the piston, alpha
// and beta in closed form at the start's tip and tilt (linear in alpha, beta cos e, beta sin e:
// no start needed for the piston, which comes back wrapped to (-pi, pi]), then Gauss-Newton on
// all five. Its residual is split as tilt-aware AIA's is: the white part (adjacent pixels'
// differences) over beta median(B) is the noise, the rest the misfit.
//
// The plate's pose (frame_pose_reference, fit_frame_pose): a reference set at steps 0, pi/2, ...
// gives a_q, b_q and phi_q (hariharan5's five frames, or four); a frame's plane is then
//   piston = (4 pi / lambda) Z,  tip = (4 pi / lambda) theta_x R,  tilt = -(4 pi / lambda) theta_y
//   R
// (fizeau_simulation.hpp, R the pupil's radius on the plate). The start is the pose the caller
// expects (the last one plus any move it commanded since): the piston is taken within a quarter
// wave of it, so the fringe order is the start's. A failure is a result with valid = false and
// the reason, never a pose:
//   beta < 0                      the fringes fit inverted: a quarter wave from the start
//   beta < min_contrast           the fringes are gone (a blocked beam, a dark frame)
//   not settled in max_iterations
//   misfit > max_misfit           not the surface the reference saw, or a tilt beyond the fit's
//                                 reach from the start
//   |d - start| > max_step_nm     at the pupil's edge: a step the fringe order cannot follow
// What it assumes: the test surface and the illumination are the reference's, the plate moves
// rigidly, and the camera's pupil is the mask's.
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "piezoshift/core/wavelength.hpp"
#include "piezoshift/psi/grid.hpp"

namespace piezoshift::psi {

//! A frame's phase shift over the pupil [rad]: piston + tip y + tilt x (pupil coordinates).
struct PhasePlane {
  double piston_rad = 0.0;
  double tip_rad = 0.0;
  double tilt_rad = 0.0;
};

//! The fringes a frame is fitted against, over the pupil's pixels.
struct PhaseReference {
  std::vector<std::size_t> pixels;       //!< row-major indices of the mask's pixels
  std::vector<double> x, y;              //!< their pupil coordinates (grid.hpp)
  std::vector<double> phase_rad;         //!< phi_q; a NaN pixel is left out of the fits
  std::vector<double> bias, modulation;  //!< a_q, b_q; both empty: uniform, fitted per frame
  double modulation_scale = 1.0;         //!< median b_q (1 when uniform): the noise's unit
  int width = 0, height = 0;
};

//! The mask's pixels and their coordinates, phase_rad NaN (to be filled), uniform. Throws
//! std::invalid_argument for an empty mask.
PhaseReference phase_reference(const Mask& mask);

struct PlaneFit {
  PhasePlane plane;
  double bias = 0.0;      //!< alpha
  double contrast = 0.0;  //!< beta
  double noise = 0.0;     //!< white residual / (beta modulation_scale)
  double misfit = 0.0;    //!< the residual beyond the white part, in the same unit
  int iterations = 0;
  bool settled = false;    //!< the last step moved no parameter of the plane by more than tolerance
  std::size_t pixels = 0;  //!< fitted
};

//! The frame (the reference's size; std::invalid_argument otherwise) fitted from start.
PlaneFit fit_phase_plane(const Map& frame, const PhaseReference& reference, const PhasePlane& start,
                         int max_iterations = 50, double tolerance_rad = 1e-7);

//! The plate's reference: a set at pi/2 steps, and the pupil's radius on the plate.
struct FramePoseReference {
  PhaseReference fringes;
  double pupil_radius_m = 0.025;  //!< FizeauParams::pupil_radius_m
};

//! frames: at least four at steps 0, pi/2, pi, 3 pi/2 (five: Hariharan's formula, which cancels a
//! step error to first order). Throws std::invalid_argument for fewer frames, sizes other than
//! the mask's, or an empty mask.
FramePoseReference frame_pose_reference(std::span<const Map> frames, const Mask& mask,
                                        double pupil_radius_m = 0.025);

struct FramePoseOptions {
  double wavelength_nm = core::kHeNeWavelength_nm;
  int max_iterations = 20;
  double tolerance_nm = 1e-4;  //!< settled: no point of the pupil moved more in the last step
  //! The least contrast taken as fringes: assumed 0.3 (a third of the reference's; the camera's
  //! noise is about 1 % of b on the twin, so well above it)
  double min_contrast = 0.3;
  //! The residual beyond the noise: 0.02 of the modulation, tilt-aware AIA's bound
  //! (PhaseOptions::max_misfit)
  double max_misfit = 0.02;
  //! The largest motion from the start at any pupil point: lambda / 8 (the closed form's edge is
  //! a quarter wave; half of it leaves the noise a margin)
  double max_step_nm = 79.1;
};

//! The plate's pose relative to the reference.
struct FramePose {
  double piston_nm = 0.0;
  double theta_x_urad = 0.0;
  double theta_y_urad = 0.0;
  double contrast = 0.0;  //!< beta
  double noise = 0.0;     //!< PlaneFit::noise
  double misfit = 0.0;    //!< PlaneFit::misfit
  int iterations = 0;
  bool valid = false;
  bool fringes_lost = false;  //!< not valid because the contrast fell below min_contrast
  std::string reason;         //!< why not valid, "" when valid
};

//! Fits frame from start (the expected pose; {} right after the reference). The frame must be the
//! reference's size (std::invalid_argument otherwise).
FramePose fit_frame_pose(const Map& frame, const FramePoseReference& reference,
                         const FramePose& start, const FramePoseOptions& options = {});

}  // namespace piezoshift::psi
