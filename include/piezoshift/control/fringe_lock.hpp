#pragma once
// The fringe lock (docs/fizeau.md): an outer loop at the camera's frame rate that holds the Fizeau
// cavity's optical path and the reference plate's tip and tilt on their set points, from the
// fringes, by correcting the pose the semi-closed loop holds. The gauges cannot see the cavity's
// drift (the air's index, the mount: plant/fizeau_cavity.hpp) nor their own excitation drift; the
// fringes see both, at the frame rate.
//
// Per frame, with m the fringes' piston [nm], theta_x and theta_y [urad] of the plate (unwrapped
// by the caller: the fringe order is the tracker's to carry) and r the set point:
//   valid frame:    e = r - m                              per axis
//                   c <- c + clamp(g e, +-max_step)        integral action; the inner loop settles
//                                                          in a few ms, so between frames it is a
//                                                          unit gain and a pure integrator is the
//                                                          whole outer controller
//                   c <- clamp(c, +-max_correction)        a lock never walks the stage out of the
//                                                          travel the operator gave it; at the
//                                                          bound it says so (saturated)
//                   state kLocked, lost_frames = 0
//   no valid frame: c held (no jump: the stage stays where the lock last put it, on its gauges),
//                   state kHolding; after max_lost_frames in a row kLost, and the caller falls
//                   back to the semi-closed loop alone; the next valid frame locks again from c
// The correction is applied to Z_d by the caller (through the kinematics, as P1..P3).
//
// Closed form (the inner loop a unit gain, the correction seen by the next frame): a constant
// offset decays as (1 - g)^n over n frames; a drift of rate v is followed with a lag of
// v / (g f) at frame rate f. Stable for 0 < g < 2 without delay, and for 0 < g < 1 with the one
// frame of delay of a camera whose exposure ends after the move (the range below).
//
// Real-time safe: no heap, no exceptions, no I/O; every member is noexcept.
#include <array>
#include <cstdint>

namespace piezoshift::control {

//! The three axes the fringes give: piston [nm], theta_x, theta_y [urad].
using FringeAxes = std::array<double, 3>;

struct FringeLockParams {
  //! g, per frame: 0.5 halves an offset each frame (assumed: 4 frames to 6 %, a lock bandwidth
  //! of about f / 9, far above the cavity's drift of minutes and below the frame rate)
  double gain_per_frame = 0.5;
  //! The largest correction one frame may add: piston [nm], theta_x, theta_y [urad]. Assumed
  //! a quarter wave of mirror motion at 632.8 nm, and a tilt that moves the pupil's edge as much
  //! at a 25 mm radius, so that a wrong frame cannot throw the stage further than a fringe.
  FringeAxes max_step{158.0, 6.3, 6.3};
  //! The largest total correction (assumed: 2 um and 80 urad, a fifth of the travel and the
  //! tilt range; the cavity drifts 8 nm rms an hour, docs/twin.md)
  FringeAxes max_correction{2000.0, 80.0, 80.0};
  //! Frames without fringes before the lock is lost (assumed: 5)
  std::uint32_t max_lost_frames = 5;
};

//! "" when p can run, else the first problem as a sentence naming the key.
constexpr const char* fringe_lock_problem(const FringeLockParams& p) noexcept {
  if (!(p.gain_per_frame > 0.0 && p.gain_per_frame <= 1.0))
    return "gain_per_frame must be in (0, 1] (one frame of delay: above 1 the lock rings)";
  for (std::size_t a = 0; a < 3; ++a) {
    if (!(p.max_step[a] > 0.0 && p.max_step[a] < 1e6))
      return "max_step must be > 0 and finite on every axis";
    if (!(p.max_correction[a] >= p.max_step[a] && p.max_correction[a] < 1e6))
      return "max_correction must be at least max_step and finite on every axis";
  }
  if (p.max_lost_frames < 1 || p.max_lost_frames > 100000)
    return "max_lost_frames must be in [1, 100000]";
  return "";
}

enum class FringeLockState : std::uint8_t {
  kOff,      //!< not started: no correction
  kLocked,   //!< the last frame corrected the pose
  kHolding,  //!< fringes lost for fewer than max_lost_frames: the correction is held
  kLost,     //!< lost for longer: the semi-closed loop alone, the correction still held
};

constexpr const char* to_string(FringeLockState s) noexcept {
  switch (s) {
    case FringeLockState::kOff:
      return "off";
    case FringeLockState::kLocked:
      return "locked";
    case FringeLockState::kHolding:
      return "holding (fringes lost)";
    case FringeLockState::kLost:
      return "lost: semi-closed loop alone";
  }
  return "unknown";
}

class FringeLock {
 public:
  //! p must pass fringe_lock_problem() (checked by the caller before the lock runs).
  constexpr explicit FringeLock(const FringeLockParams& p) noexcept : p_(p) {}

  //! Locks onto set point r (the fringes' pose to hold) with no correction yet.
  constexpr void start(const FringeAxes& r) noexcept {
    r_ = r;
    c_ = {};
    lost_ = 0;
    saturated_ = false;
    state_ = FringeLockState::kLocked;
  }
  //! Moves the set point (a PSI step relative to the locked cavity); the correction stays.
  constexpr void set_point(const FringeAxes& r) noexcept { r_ = r; }

  //! One frame: its measured pose m when valid (a non-finite m counts as no frame). Returns the
  //! correction in force after it.
  constexpr const FringeAxes& update(const FringeAxes& m, bool valid) noexcept {
    if (state_ == FringeLockState::kOff)
      return c_;
    // A frame whose numbers are not finite (a fit gone wrong) is no frame.
    for (double x : m)
      valid = valid && x - x == 0.0;
    if (!valid) {
      ++lost_;
      state_ = lost_ >= p_.max_lost_frames ? FringeLockState::kLost : FringeLockState::kHolding;
      return c_;
    }
    lost_ = 0;
    state_ = FringeLockState::kLocked;
    saturated_ = false;
    for (std::size_t a = 0; a < 3; ++a) {
      const double step = clamp(p_.gain_per_frame * (r_[a] - m[a]), p_.max_step[a]);
      const double c = c_[a] + step;
      c_[a] = clamp(c, p_.max_correction[a]);
      saturated_ = saturated_ || c_[a] != c;
    }
    return c_;
  }

  constexpr const FringeAxes& correction() const noexcept { return c_; }
  constexpr const FringeAxes& set_point() const noexcept { return r_; }
  constexpr FringeLockState state() const noexcept { return state_; }
  //! The last valid frame put a correction at max_correction.
  constexpr bool saturated() const noexcept { return saturated_; }
  constexpr std::uint32_t lost_frames() const noexcept { return lost_; }

 private:
  static constexpr double clamp(double x, double bound) noexcept {
    return x > bound ? bound : (x < -bound ? -bound : x);
  }

  FringeLockParams p_;
  FringeAxes r_{};
  FringeAxes c_{};
  std::uint32_t lost_ = 0;
  bool saturated_ = false;
  FringeLockState state_ = FringeLockState::kOff;
};

}  // namespace piezoshift::control
