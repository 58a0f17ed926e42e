#include "piezoshift/instrument/sample_sequence.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"

namespace piezoshift::instrument {

namespace {

// Z_d as the loop reports it against what was commanded: the GCS pose goes through the stage
// model and back, so equal to rounding, far below a nanometre.
constexpr double kAppliedTolerance_um = 1e-6;

double seconds_between(std::chrono::steady_clock::time_point a,
                       std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

}  // namespace

SampleSequence::SampleSequence(camera::Camera& camera, const SequenceParams& params,
                               double period_s, Move move)
    : camera_(camera),
      p_(params),
      period_s_(period_s),
      move_(std::move(move)),
      total_(static_cast<std::size_t>(params.averages) * params.steps_rad.size()),
      window_(params.on_target, period_s),
      exposure_ticks_(static_cast<std::size_t>(
          std::max(1L, std::lround(camera.settings().exposure_s / period_s)))) {
  if (const std::string why = sequence_problem(params); !why.empty())
    throw core::InputError("measurement: " + why);
  result_.frames.reserve(total_);
  result_.exposures.reserve(total_);
  result_.floor_s = sequence_floor_s(params, window_.length(), period_s, camera.settings());
}

void SampleSequence::fail(const std::string& why) {
  result_.validity.fail(why);
  phase_ = Phase::kDone;
}

void SampleSequence::command(double z_um) {
  previous_um_ = target_um_;
  has_previous_ = phase_ != Phase::kStart;
  target_um_ = z_um;
  applied_ = false;
  if (const std::string why = move_(z_um); !why.empty()) {
    fail(fmt::format("the move to Z_d = {:.4f} um was refused: {}", z_um, why));
    return;
  }
  phase_ = Phase::kApply;
}

camera::PlatePose SampleSequence::relative(const LoopSample& s) const {
  if (!s.has_truth)
    return {s.t_s, 0.0, 0.0, 0.0};
  return camera::relative_to(s.pose, origin_);
}

std::string SampleSequence::moved_away(const LoopSample& s) const {
  return fmt::format(
      "the stage was moved away from the measurement's Z_d = {:.4f} um at {:.3f} s "
      "(Z_d {:.4f}, {:.4f}, {:.4f} um: another client's move, a wave generator or a stop)",
      target_um_, s.t_s, s.zd_um[0], s.zd_um[1], s.zd_um[2]);
}

// The checks every sample passes once the first move is applied; false when the sequence ends.
bool SampleSequence::watch(const LoopSample& s) {
  if (s.faulted) {
    fail(fmt::format("the safety supervisor latched {} at {:.3f} s", s.fault, s.t_s));
    return false;
  }
  bool at_target = true;
  for (double z : s.zd_um)
    at_target = at_target && std::fabs(z - target_um_) <= kAppliedTolerance_um;
  if (!applied_) {
    // Until this move shows, Z_d is the last target's: any other value is a move not ours (one
    // whose own samples we had not yet read when we moved, or one made after ours).
    bool ours = true;
    for (double z : s.zd_um)
      ours = ours && (std::fabs(z - target_um_) <= kAppliedTolerance_um || !has_previous_ ||
                      std::fabs(z - previous_um_) <= kAppliedTolerance_um);
    if (!ours) {
      fail(moved_away(s));
      return false;
    }
    applied_ = at_target && s.closed_loop;
    if (!applied_ && s.t_s - phase_t0_s_ > p_.on_target.timeout_s)
      fail(fmt::format("the loop did not apply the move to Z_d = {:.4f} um within {} s", target_um_,
                       p_.on_target.timeout_s));
    return applied_;
  }
  if (!s.closed_loop) {
    fail(fmt::format("the servo went off at {:.3f} s (SVO 0 from a client?)", s.t_s));
    return false;
  }
  if (!at_target) {
    fail(moved_away(s));
    return false;
  }
  return true;
}

void SampleSequence::feed(const LoopSample& s) {
  if (phase_ == Phase::kDone)
    return;
  const bool gap = have_tick_ && s.tick != last_tick_ + 1;
  last_tick_ = s.tick;
  have_tick_ = true;
  last_t_s_ = s.t_s;
  ++result_.ticks;
  result_.overruns += s.overrun ? 1 : 0;
  camera_.observe_plate(relative(s));
  if (phase_ == Phase::kStart) {
    // Its first move would switch the servo on, which clears a latched fault: that is the
    // operator's to do, knowing why it latched.
    if (s.faulted) {
      fail(fmt::format("the safety supervisor has {} latched: clear it (SVO) before measuring",
                       s.fault));
      return;
    }
    phase_t0_s_ = s.t_s;
    command(p_.base_um);
    return;
  }
  const bool was_applied = applied_;
  if (!watch(s))
    return;
  if (!was_applied) {  // applied with this sample
    phase_t0_s_ = s.t_s;
    window_.reset();
    phase_ = based_ ? Phase::kSettle : Phase::kHold;
  }
  switch (phase_) {
    case Phase::kHold:
      if (s.t_s - phase_t0_s_ >= p_.initial_settle_s) {
        phase_t0_s_ = s.t_s;
        phase_ = Phase::kSettle;
      }
      break;
    case Phase::kSettle:
      if (gap)
        window_.reset();  // the window holds consecutive ticks only
      if (window_.add(s.gauge_error_nm))
        on_settled(s);
      else if (s.t_s - phase_t0_s_ >= p_.on_target.timeout_s)
        fail(window_.timeout_reason(s.t_s));
      break;
    case Phase::kTrigger:
      if (camera_.trigger(s.t_s)) {
        rec_.trigger_time_s = s.t_s;
        camera_.observe_plate(relative(s));  // the exposure's first instant
        result_.exposures.push_back(rec_);
        exposure_.begin(relative(s));
        phase_ = Phase::kExpose;
      } else if (s.t_s - phase_t0_s_ > p_.frame_timeout_s) {
        fail(fmt::format("camera {} took no trigger for {} s: {}", camera_.name(),
                         p_.frame_timeout_s, camera_.message()));
      }
      break;
    case Phase::kExpose:
      exposure_.add(s.gauge_error_nm, relative(s));
      if (exposure_.ticks() >= exposure_ticks_)
        finish_exposure(s);
      break;
    default:
      break;
  }
}

void SampleSequence::on_settled(const LoopSample& s) {
  if (!based_) {
    based_ = true;
    origin_ = s.has_truth ? s.pose : camera::PlatePose{};
    start_wall_ = Clock::now();
    start_loop_s_ = s.t_s;
    next_frame(s);
    return;
  }
  rec_.settled_time_s = s.t_s;
  phase_t0_s_ = s.t_s;
  phase_ = Phase::kTrigger;
}

void SampleSequence::next_frame(const LoopSample& s) {
  rec_ = planned_exposure(p_, next_, s.t_s);
  ++next_;
  phase_t0_s_ = s.t_s;
  command(p_.base_um + rec_.commanded_piston_nm * 1e-3);
}

void SampleSequence::finish_exposure(const LoopSample& s) {
  exposure_.finish(result_.exposures.back(), s.has_truth, s.t_s);
  if (next_ < total_) {
    next_frame(s);
    return;
  }
  phase_ = Phase::kCollect;
  collect_from_ = Clock::now();
}

void SampleSequence::poll() {
  if (phase_ == Phase::kDone)
    return;
  for (;;) {
    camera::Frame f;
    const camera::FrameStatus st = camera_.poll(f);
    if (st == camera::FrameStatus::kNone)
      break;
    if (const std::string why =
            take_frame(st, f, camera_, seconds_between(start_wall_, Clock::now()), result_);
        !why.empty()) {
      fail(why);
      return;
    }
  }
  if (phase_ != Phase::kCollect)
    return;
  if (result_.frames.size() == total_) {
    result_.loop_time_s = last_t_s_ - start_loop_s_;
    result_.wall_time_s = seconds_between(start_wall_, Clock::now());
    phase_ = Phase::kDone;
  } else if (seconds_between(collect_from_, Clock::now()) > p_.frame_timeout_s) {
    fail(fmt::format("camera {}: {} of {} frames arrived within {} s of the last exposure",
                     camera_.name(), result_.frames.size(), total_, p_.frame_timeout_s));
  }
}

}  // namespace piezoshift::instrument
