#include "piezoshift/instrument/fringe_lock_session.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include <fmt/core.h>

#include "piezoshift/instrument/measurement.hpp"
#include "piezoshift/instrument/sequence.hpp"
#include "piezoshift/psi/pupil_detection.hpp"

namespace piezoshift::instrument {

namespace {

// The reference takes the first four or five frames at k pi/2.
std::size_t reference_frames(const SequenceParams& p) {
  std::size_t n = 0;
  while (n < p.steps_rad.size() && n < 5 &&
         std::fabs(p.steps_rad[n] - static_cast<double>(n) * std::numbers::pi / 2.0) < 1e-9)
    ++n;
  return n;
}

}  // namespace

std::string lock_problem(const LockSetup& setup, const SequenceParams& params) {
  if (reference_frames(params) < 4)
    return "the fringe lock takes its reference from the first frames, which must be at steps 0, "
           "pi/2, pi and 3 pi/2 (hariharan5, 4step, or --steps-rad beginning so)";
  if (const char* why = control::fringe_lock_problem(setup.lock); why[0] != '\0')
    return fmt::format("the fringe lock: {}", why);
  if (setup.mask.size() > 0 && setup.mask.count() < 16)
    return "the fringe lock needs the pupil on the camera (a mask of 16 pixels or more)";
  if (!setup.tripod)
    return "the fringe lock needs the tripod's points P1..P3";
  if (!(setup.pupil_radius_m > 0.0))
    return "the fringe lock needs the pupil's radius on the plate";
  if (!(setup.retake_s > 0.0 && setup.retake_s <= 60.0))
    return fmt::format("the fringe lock's retake time {} s: must be in (0, 60]", setup.retake_s);
  return {};
}

FringeLockSession::FringeLockSession(const LockSetup& setup, const SequenceParams& params)
    : s_(setup),
      reference_count_(reference_frames(params)),
      locks_(params.steps_rad.size(), control::FringeLock(setup.lock)) {
  if (const std::string why = lock_problem(setup, params); !why.empty())
    throw std::invalid_argument(why);
  s_.pose.wavelength_nm = params.wavelength_nm;
}

kinematics::PointDisplacements FringeLockSession::points_um(double base_um,
                                                            double commanded_piston_nm,
                                                            std::size_t step) {
  const control::FringeAxes c = locks_.at(step).correction();
  applied_by_move_.push_back(c);
  return s_.tripod->inverse({base_um + 1e-3 * (commanded_piston_nm + c[0]), c[1], c[2]});
}

void FringeLockSession::begin_hold() {
  holding_ = true;
  locks_.front().set_point(frame0_);
}

bool FringeLockSession::find_pupil() {
  summary_.pupil_from_modulation = s_.mask.size() == 0;
  if (summary_.pupil_from_modulation) {
    try {
      s_.mask = psi::pupil_from_modulation(reference_frames_).mask;
    } catch (const std::invalid_argument& e) {
      problem_ =
          fmt::format("the fringe lock found no pupil in its reference frames: {}", e.what());
      return false;
    }
    if (s_.mask.count() < 16) {
      problem_ = fmt::format(
          "the fringe lock found {} pixels of pupil in its reference frames' modulation (16 or "
          "more needed)",
          s_.mask.count());
      return false;
    }
  }
  summary_.pupil_pixels = s_.mask.count();
  return true;
}

void FringeLockSession::on_frame(const camera::Frame& frame, ExposureRecord& rec) {
  if (!problem_.empty())
    return;
  const std::size_t n = frames_++;
  // Each frame takes its move's correction off the queue: a minute's hold of 4300 frames keeps
  // one or two, not one per move of the whole run.
  control::FringeAxes applied{};
  if (!applied_by_move_.empty()) {
    applied = applied_by_move_.front();
    applied_by_move_.pop_front();
  }
  rec.lock_correction_nm = applied[0];
  last_lost_fringes_ = false;
  if (n < reference_count_) {
    reference_frames_.push_back(frame_maps({frame}).front());
    rec.lock_state = "reference";
    if (reference_frames_.size() == reference_count_) {
      if (!find_pupil())
        return;
      reference_ = psi::frame_pose_reference(reference_frames_, s_.mask, s_.pupil_radius_m);
      // Frame 0's own pose: the reference's piston is a fit over its frames, which sets it
      // apart from frame 0's by a fraction of a nanometre; the hold returns to frame 0.
      const psi::FramePose f0 =
          psi::fit_frame_pose(reference_frames_.front(), *reference_, {}, s_.pose);
      if (f0.valid)
        frame0_ = {f0.piston_nm, f0.theta_x_urad, f0.theta_y_urad};
      reference_frames_.clear();
      summary_.reference_frames = reference_count_;
      for (control::FringeLock& l : locks_)
        l.start({0.0, 0.0, 0.0});  // frame 0's pose: the base
      last_ = {};
      last_.valid = true;
      last_commanded_nm_ = 0.0;
      last_applied_ = {};
    }
    return;
  }
  // Expected: the last valid pose, moved by what was commanded and corrected since.
  psi::FramePose start = last_;
  start.piston_nm += rec.commanded_piston_nm - last_commanded_nm_ + applied[0] - last_applied_[0];
  start.theta_x_urad += applied[1] - last_applied_[1];
  start.theta_y_urad += applied[2] - last_applied_[2];
  const psi::FramePose m =
      psi::fit_frame_pose(frame_maps({frame}).front(), *reference_, start, s_.pose);
  control::FringeLock& lock = locks_.at(static_cast<std::size_t>(rec.frame));
  if (!holding_)  // the hold's set point is frame 0's pose (begin_hold)
    lock.set_point({rec.commanded_piston_nm, 0.0, 0.0});
  lock.update({m.piston_nm, m.theta_x_urad, m.theta_y_urad}, m.valid);
  rec.lock_state = control::to_string(lock.state());
  if (m.valid) {
    rec.fringe_piston_nm = m.piston_nm;
    last_ = m;
    last_commanded_nm_ = rec.commanded_piston_nm;
    last_applied_ = applied;
    ++summary_.locked;
  } else {
    rec.lock_reason = m.reason;
    last_lost_fringes_ = m.fringes_lost;
    ++summary_.holding;
    if (lock.state() == control::FringeLockState::kLost)
      ++summary_.lost;
    if (summary_.first_refusal.empty())
      summary_.first_refusal = fmt::format("frame {}: {}", n, m.reason);
  }
  summary_.correction = lock.correction();
}

}  // namespace piezoshift::instrument
