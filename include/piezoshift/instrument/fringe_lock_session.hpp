#pragma once
// The fringe lock in a phase-shifting sequence (docs/fizeau.md): the sequence's own frames hold the
// Fizeau cavity, so its steps are made relative to the locked cavity and not to the gauges.
//
//   the reference: the first average's first frames, at steps 0, pi/2, pi, 3 pi/2 (and 2 pi)
//                  (psi::frame_pose_reference; the sequence's steps must begin so), taken on the
//                  semi-closed loop alone; every step's lock starts at the pose of frame 0
//   every frame after: its pose fitted against the reference (psi::fit_frame_pose), from the
//                  pose expected of it (the last valid one, moved by what was commanded and
//                  corrected since), then the lock of its step (one control::FringeLock per
//                  frame of an average) with the frame's commanded piston as its set point
//   every move:    Z_d of P1..P3 = base + commanded piston + its step's correction, the
//                  correction's tip and tilt through the tripod (kinematics/tripod.hpp)
// One lock per step, not one for all: a step's error that repeats every average (the stage's
// step gain and nonlinearity left by the calibration, 1 to 2 nm on the twin) is learnt by that
// step's lock alone, and no correction changes between two frames of a set for the frame
// before's sake (one lock chasing each step's error in turn made the steps worse: on the twin
// with the cavity's drift, measured 0.29 nm of surface error against 0.22 nm unlocked).
// A hold after the sequence (SequenceParams::hold_s) is frame 0 again and again: step 0's lock,
// which the averages have taught, holds the cavity frame by frame.
// The pupil: the mask given (the twin camera's scene), else found from the reference frames'
// fringe modulation (psi::pupil_from_modulation, as a measurement's own mask is), which any
// camera has: none found there ends the sequence with the reason (problem()).
// A frame whose pose is not valid (fringes lost, a misfit, a step the fringe order cannot
// follow) leaves its step's correction where it is: the stage stays on its gauges without a
// jump (FringeLock's holding, then lost), and each exposure records the lock's state and why.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "piezoshift/camera/frame.hpp"
#include "piezoshift/control/fringe_lock.hpp"
#include "piezoshift/kinematics/tripod.hpp"
#include "piezoshift/psi/frame_pose.hpp"
#include "piezoshift/psi/grid.hpp"

namespace piezoshift::instrument {

struct SequenceParams;
struct ExposureRecord;

struct LockSetup {
  control::FringeLockParams lock{};
  psi::FramePoseOptions pose{};
  double pupil_radius_m = 0.025;  //!< the pupil on the plate (camera::CameraConfig)
  psi::Mask mask;  //!< the pupil on the camera; empty: from the reference frames' modulation
  //! P1..P3 on the plate: the correction's tilt to the points' set-points
  std::optional<kinematics::TripodGeometry> tripod;
  //! A frame of the sequence whose fringes were lost (psi::FramePose::fringes_lost) is taken
  //! again, until they come back, for at most this long of loop time from its first try; then
  //! the sequence fails. The hold's frames are not taken again.
  double retake_s = 1.0;
};

//! "" when a sequence with these steps can be locked, else why not: the steps begin 0, pi/2, pi,
//! 3 pi/2 (to 1e-9), the lock's parameters are in range (retake_s in (0, 60]), a mask given has
//! 16 pixels or more, the tripod set.
std::string lock_problem(const LockSetup& setup, const SequenceParams& params);

//! What the lock did over a sequence.
struct LockSummary {
  std::size_t reference_frames = 0;
  std::size_t locked = 0;              //!< frames whose pose corrected the stage
  std::size_t holding = 0;             //!< frames without a valid pose, the correction held
  std::size_t lost = 0;                //!< ... of which beyond max_lost_frames in a row
  std::size_t retaken = 0;             //!< frames taken again because their fringes were lost
  std::string first_refusal;           //!< the first frame's reason for no pose ("" if none)
  control::FringeAxes correction{};    //!< the last frame's step's, at the end [nm, urad, urad]
  bool pupil_from_modulation = false;  //!< the pupil found in the reference frames, not given
  std::size_t pupil_pixels = 0;        //!< the pupil's pixels (0 before the reference)
};

class FringeLockSession {
 public:
  //! setup must pass lock_problem() with params (std::invalid_argument otherwise).
  FringeLockSession(const LockSetup& setup, const SequenceParams& params);

  //! Z_d of P1..P3 [um] for the move to base_um + commanded_piston_nm, frame `step` of an
  //! average.
  kinematics::PointDisplacements points_um(double base_um, double commanded_piston_nm,
                                           std::size_t step);
  //! The frame of exposure `rec` (in order, one per move); it feeds the lock of rec.frame's step
  //! (a hold's frames: frame 0's). Records the lock's doing in rec.
  void on_frame(const camera::Frame& frame, ExposureRecord& rec);

  const LockSummary& summary() const noexcept { return summary_; }
  //! The last frame on_frame() saw had lost its fringes (after the reference).
  bool last_frame_lost_fringes() const noexcept { return last_lost_fringes_; }
  //! Why the lock cannot go on ("": it can): no pupil in the reference frames' modulation. The
  //! sequence then fails with it; later frames are ignored.
  const std::string& problem() const noexcept { return problem_; }
  //! The sequence takes the last frame again.
  void note_retake() noexcept { ++summary_.retaken; }
  //! The hold begins: from here every move and frame is step 0's lock's, which holds the cavity
  //! where frame 0 of the first average found it (that frame's pose against the reference).
  void begin_hold();

 private:
  bool find_pupil();  // at the reference's end: the mask given, else from its modulation

  LockSetup s_;
  std::size_t reference_count_;
  std::vector<psi::Map> reference_frames_;
  std::optional<psi::FramePoseReference> reference_;
  std::vector<control::FringeLock> locks_;  //!< one per frame of an average
  bool holding_ = false;                    //!< from begin_hold()
  control::FringeAxes frame0_{};            //!< frame 0's pose: the hold's set point
  psi::FramePose last_{};                   //!< the last valid pose
  double last_commanded_nm_ = 0.0;          //!< its frame's commanded piston
  control::FringeAxes last_applied_{};      //!< the correction its frame was taken with
  control::FringeAxes applied_{};           //!< the correction of the last move
  //! per move whose frame has not come yet, in order (frames come one per move, in order)
  std::deque<control::FringeAxes> applied_by_move_;
  std::size_t frames_ = 0;
  bool last_lost_fringes_ = false;
  std::string problem_;
  LockSummary summary_;
};

}  // namespace piezoshift::instrument
