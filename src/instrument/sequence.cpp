#include "piezoshift/instrument/sequence.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <functional>
#include <numbers>
#include <string>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/core/wall_time.hpp"
#include "piezoshift/instrument/exposure_accumulator.hpp"
#include "piezoshift/instrument/fit_thread.hpp"
#include "piezoshift/instrument/settle_window.hpp"

namespace piezoshift::instrument {

namespace {

using Clock = std::chrono::steady_clock;
using core::seconds_since;

// Drives one sequence: the loop's ticks, the settle criterion, the camera's triggers and frames.
class Runner {
 public:
  Runner(runtime::ControlLoop& loop, const plant::Twin* twin, camera::Camera& camera,
         const SequenceParams& p, const rig::Progress& progress)
      : loop_(loop),
        twin_(twin),
        camera_(camera),
        p_(p),
        progress_(progress),
        period_s_(static_cast<double>(loop.period_ns()) * 1e-9),
        total_(static_cast<std::size_t>(p.averages) * p.steps_rad.size()),
        window_(p.on_target, period_s_) {
    result_.frames.reserve(total_);
    result_.exposures.reserve(total_);
    if (p.lock)
      lock_.emplace(*p.lock, p);
    if (p.lock && loop.real_time())
      fit_thread_.emplace();
  }

  SequenceResult run() {
    loop_.start();
    const double z = p_.base_um;
    loop_.drive_points({z, z, z});
    if (run_for(p_.initial_settle_s) && settle()) {
      origin_ = raw_pose();
      start_wall_ = Clock::now();
      start_loop_s_ = now_s();
      for (int a = 0; a < p_.averages && ok(); ++a)
        for (std::size_t k = 0; k < p_.steps_rad.size() && ok(); ++k)
          take_frame(a, static_cast<int>(k));
      if (ok())
        collect_remaining_frames();
      if (ok() && p_.hold_s > 0.0)
        hold();
      result_.loop_time_s = now_s() - start_loop_s_;
      result_.wall_time_s = seconds_since(start_wall_);
    }
    finish_loop();
    if (fit_thread_)
      fit_thread_->wait();  // a fit still running after a failure writes to result_
    if (lock_)
      result_.lock = lock_->summary();
    result_.floor_s = sequence_floor_s(p_, window_.length(), period_s_, camera_.settings());
    return std::move(result_);
  }

 private:
  bool ok() const { return result_.validity.valid; }
  double now_s() const { return static_cast<double>(loop_.ticks()) * period_s_; }

  void fail(const std::string& why) { result_.validity.fail(why); }

  camera::PlatePose raw_pose() const {
    if (twin_ == nullptr)
      return {now_s(), 0.0, 0.0, 0.0};
    const plant::TwinTruth& t = twin_->truth();
    return {now_s(), twin_->fringe_piston_nm(), t.theta_x_urad, t.theta_y_urad};
  }

  camera::PlatePose pose() const { return camera::relative_to(raw_pose(), origin_); }

  // One loop tick, then the plate's pose to the camera and any frame that has arrived.
  bool tick() {
    if (!loop_.tick()) {
      ended_ = true;
      note_loop_end();
      return false;
    }
    if (loop_.trigger_pulses() > edges_forwarded_)
      forward_trigger_edge();
    camera_.observe_plate(pose());
    poll_frames();
    if (loop_.result().fault_detected) {
      note_loop_end();
      return false;
    }
    return ok();
  }

  void note_loop_end() {
    const runtime::LoopResult& r = loop_.result();
    if (r.fault_detected)
      fail(fmt::format("the safety supervisor latched {} at {:.3f} s{}",
                       runtime::to_string(r.fault.reason),
                       static_cast<double>(r.fault.tick) * period_s_,
                       r.fault.channel >= 0 ? fmt::format(" on channel {}", r.fault.channel + 1)
                                            : std::string()));
    else if (r.stop_reason == runtime::StopReason::kSignal)
      fail(fmt::format("stopped by signal {}", r.signal));
    else if (ended_)
      fail("the loop ended before the sequence did");
  }

  bool run_for(double duration_s) {
    const auto n = std::max(0L, std::lround(duration_s / period_s_));
    for (long k = 0; k < n; ++k)
      if (!tick())
        return false;
    return true;
  }

  // S - feedback per channel [nm], the controller's own estimate of this tick.
  std::array<double, 3> gauge_error_nm() const {
    const control::ControllerOutput& out = loop_.last_cycle().controller;
    std::array<double, 3> e{};
    for (std::size_t i = 0; i < 3; ++i)
      e[i] = 1000.0 * (out.target_um[i] - out.feedback_um[i]);
    return e;
  }

  // Ticks until the settle criterion holds (settle_window.hpp).
  bool settle() {
    const double t0 = now_s();
    window_.reset();
    while (now_s() - t0 < p_.on_target.timeout_s) {
      if (!tick())
        return false;
      if (window_.add(gauge_error_nm()))
        return true;
    }
    fail(window_.timeout_reason(now_s()));
    return false;
  }

  // The hold: frame 0's position, frame after frame, until hold_s of loop time has passed.
  void hold() {
    holding_ = true;
    if (lock_)
      lock_->begin_hold();
    const double t0 = now_s();
    while (ok() && now_s() - t0 < p_.hold_s) {
      ExposureRecord rec = planned_exposure(p_, 0, now_s());
      rec.average = p_.averages;  // after the last average
      loop_.drive_points(lock_ ? lock_->points_um(p_.base_um, 0.0, 0)
                               : runtime::Vec3{p_.base_um, p_.base_um, p_.base_um});
      if (!settle())
        return;
      rec.settled_time_s = now_s();
      if (!trigger_when_ready(rec))
        return;
      result_.hold.push_back(rec);
      if (!expose(result_.hold.back()))
        return;
      await_frames(result_.hold.size());
      if (progress_)
        progress_(std::min(now_s() - t0, p_.hold_s), p_.hold_s, "s of hold");
    }
    if (ok())
      collect_remaining_frames();
  }

  // Frames in of the current phase (the sequence's, then the hold's) and frames asked for.
  std::size_t received() const { return holding_ ? hold_frames_ : result_.frames.size(); }
  std::size_t expected() const { return holding_ ? result_.hold.size() : total_; }
  std::vector<ExposureRecord>& records() { return holding_ ? result_.hold : result_.exposures; }

  // A frame of the sequence; with the lock, taken again while its fringes are lost (retake_s).
  void take_frame(int average, int frame) {
    const double first_try_s = now_s();
    for (int retakes = 0; take_frame_once(average, frame, retakes); ++retakes) {
      if (lock_ && !lock_->problem().empty()) {
        fail(lock_->problem());
        return;
      }
      if (!lock_ || !lock_->last_frame_lost_fringes()) {
        if (progress_)
          progress_(static_cast<double>(result_.exposures.size()), static_cast<double>(total_),
                    "frames");
        return;
      }
      if (now_s() - first_try_s > p_.lock->retake_s) {
        fail(
            fmt::format("frame {} of average {}: the fringes did not come back within {} s "
                        "(first tried at {:.3f} s): {}",
                        frame, average + 1, p_.lock->retake_s, first_try_s,
                        result_.exposures.back().lock_reason));
        return;
      }
      result_.frames.pop_back();  // no fringes: dropped, and taken again
      result_.exposures.pop_back();
      lock_->note_retake();
    }
  }

  // One try: move, settle, expose; off a real-time clock, its frame in (false: the sequence
  // failed).
  bool take_frame_once(int average, int frame, int retakes) {
    ExposureRecord rec = planned_exposure(
        p_,
        static_cast<std::size_t>(average) * p_.steps_rad.size() + static_cast<std::size_t>(frame),
        now_s());
    const double z = p_.base_um + rec.commanded_piston_nm * 1e-3;
    loop_.drive_points(lock_ ? lock_->points_um(p_.base_um, rec.commanded_piston_nm,
                                                static_cast<std::size_t>(frame))
                             : runtime::Vec3{z, z, z});
    rec.retakes = retakes;
    if (!settle())
      return false;
    rec.settled_time_s = now_s();
    if (!trigger_when_ready(rec))
      return false;
    // Recorded from the trigger on: the frame may arrive before the exposure's last tick ends.
    result_.exposures.push_back(rec);
    if (!expose(result_.exposures.back()))
      return false;
    await_frames(result_.exposures.size());
    return ok();
  }

  // The camera refuses a trigger while it reads out the previous frame: tick until it takes one.
  bool trigger_when_ready(ExposureRecord& rec) {
    if (p_.trigger == TriggerMode::kLine)
      return arm_when_ready();
    const double t0 = now_s();
    while (!camera_.trigger(now_s())) {
      if (now_s() - t0 > p_.frame_timeout_s) {
        fail(fmt::format("camera {} took no trigger for {} s: {}", camera_.name(),
                         p_.frame_timeout_s, camera_.message()));
        return false;
      }
      if (!tick())
        return false;
    }
    rec.trigger_time_s = now_s();
    camera_.observe_plate(pose());  // the exposure's first instant
    return true;
  }

  // A line-triggered camera cannot refuse an edge, so the pulse waits (as trigger() would be
  // refused) until the camera's exposure and readout since the previous edge are over.
  bool arm_when_ready() {
    const camera::CameraSettings& cs = camera_.settings();
    const double t0 = now_s();
    while (edges_forwarded_ > 0 && now_s() < last_edge_s_ + cs.exposure_s + cs.readout_s - 1e-9) {
      if (now_s() - t0 > p_.frame_timeout_s) {
        fail(fmt::format("camera {} not ready for {} s", camera_.name(), p_.frame_timeout_s));
        return false;
      }
      if (!tick())
        return false;
    }
    if (!loop_.arm_trigger_pulse(p_.trigger_pulse_ticks)) {
      fail(
          fmt::format("the trigger line of DAQ {} took no pulse at {:.3f} s (the previous one "
                      "still high?)",
                      loop_.daq().name(), now_s()));
      return false;
    }
    edge_pose_ = pose();  // the exposure's first instant: the state the raising tick starts from
    return true;
  }

  // The rising edge the last tick put out, to the camera before that tick's pose, as a wire would
  // carry it: the twin's from its backend's record of the line, else (hardware: the wire is a
  // cable) the loop's report, which a line-triggered camera takes as its frame's time.
  void forward_trigger_edge() {
    runtime::TriggerEdge edge = loop_.last_trigger_edge();
    runtime::TriggerEdge recorded{};
    if (loop_.daq().take_trigger_edge(recorded))
      edge = recorded;
    edges_forwarded_ = loop_.trigger_pulses();
    // On the records' and the poses' clock (ticks x T): the edge's scheduled time unless slots
    // were skipped before it, when the scheduled time is later by them and a camera triggered
    // at it would wait for poses the sequence labels earlier, past its exposure's last tick.
    last_edge_s_ = static_cast<double>(edge.tick) * period_s_;
    if (records().empty())
      return;
    records().back().trigger_time_s = last_edge_s_;
    if (!camera_.trigger(last_edge_s_)) {
      fail(fmt::format("camera {} took no trigger from the line's edge at {:.3f} s: {}",
                       camera_.name(), last_edge_s_, camera_.message()));
      return;
    }
    camera_.observe_plate(edge_pose_);
  }

  // Ticks through the exposure, the stage's state recorded tick by tick.
  bool expose(ExposureRecord& rec) {
    const auto n = std::max(1L, std::lround(camera_.settings().exposure_s / period_s_));
    ExposureAccumulator acc;
    acc.begin(pose());
    for (long k = 0; k < n; ++k) {
      if (!tick())
        return false;
      acc.add(gauge_error_nm(), pose());
    }
    acc.finish(rec, twin_ != nullptr, now_s());
    return true;
  }

  void poll_frames() {
    camera::Frame f;
    for (;;) {
      const camera::FrameStatus s = camera_.poll(f);
      if (s == camera::FrameStatus::kNone)
        return;
      if (!accept(s, f))
        return;
    }
  }

  bool accept(camera::FrameStatus s, camera::Frame& f) {
    if (holding_)
      return accept_hold_frame(s, f);
    if (const std::string why =
            instrument::take_frame(s, f, camera_, seconds_since(start_wall_), result_);
        !why.empty()) {
      fail(why);
      return false;
    }
    if (lock_) {  // its correction is in force from the next move
      const std::size_t n = result_.frames.size() - 1;
      feed_lock([this, n] { lock_->on_frame(result_.frames[n], result_.exposures[n]); });
    }
    return true;
  }

  // A hold's frame: to the lock, if any, then dropped.
  bool accept_hold_frame(camera::FrameStatus s, camera::Frame& f) {
    std::string why;
    if (s == camera::FrameStatus::kLost)
      why = fmt::format("camera {} lost frame {} of the hold", camera_.name(), f.frame_id);
    else if (s != camera::FrameStatus::kOk)
      why = fmt::format("camera {}: {} ({})", camera_.name(), camera::to_string(s),
                        camera_.message());
    else if (hold_frames_ >= result_.hold.size())
      why = fmt::format("camera {} delivered frame {} that no trigger asked for", camera_.name(),
                        f.frame_id);
    if (!why.empty()) {
      fail(why);
      return false;
    }
    const std::size_t k = hold_frames_++;
    result_.hold[k].frame_id = f.frame_id;
    result_.hold[k].arrival_wall_s = seconds_since(start_wall_);
    if (lock_)
      feed_lock([this, k, frame = std::move(f)] { lock_->on_frame(frame, result_.hold[k]); });
    return true;
  }

  // A frame to the lock: here off a real-time clock (the loop's time stands still meanwhile),
  // else on the fit thread while the loop ticks.
  void feed_lock(std::function<void()> job) {
    if (fit_thread_)
      fit_thread_->run(std::move(job));
    else
      job();
  }

  // After an exposure: off a real-time clock, its frame in; on one with the lock, the loop
  // holding until the frame is in and its fit done, so that the next move takes its correction
  // and a frame whose fringes were lost can be taken again, as off a real-time clock. On a
  // real-time clock without the lock the frames come in while the sequence moves on.
  void await_frames(std::size_t count) {
    if (!loop_.real_time()) {
      wait_for_frames(count);
      return;
    }
    if (!fit_thread_)
      return;
    const auto t0 = Clock::now();
    while (ok() && (received() < count || !fit_thread_->idle())) {
      if (seconds_since(t0) > p_.frame_timeout_s) {
        fail(fmt::format("camera {}: frame {}{} and its fit not done within {} s", camera_.name(),
                         count - 1, holding_ ? " of the hold" : "", p_.frame_timeout_s));
        return;
      }
      tick();
    }
  }

  // Off a real-time clock only: the loop's time stands still while this thread waits.
  void wait_for_frames(std::size_t count) {
    while (ok() && received() < count) {
      camera::Frame f;
      const camera::FrameStatus s = camera_.wait(f, p_.frame_timeout_s);
      if (s == camera::FrameStatus::kTimeout) {
        fail(fmt::format("camera {}: frame {}{} did not arrive within {} s", camera_.name(),
                         received(), holding_ ? " of the hold" : "", p_.frame_timeout_s));
        return;
      }
      accept(s, f);
    }
  }

  // On a real-time clock the loop keeps holding the last position while the frames come in.
  void collect_remaining_frames() {
    if (!loop_.real_time()) {
      wait_for_frames(expected());
      return;
    }
    const auto t0 = Clock::now();
    while (ok() && received() < expected()) {
      if (seconds_since(t0) > p_.frame_timeout_s) {
        fail(fmt::format("camera {}: {} of {} frames{} arrived within {} s of the last exposure",
                         camera_.name(), received(), expected(), holding_ ? " of the hold" : "",
                         p_.frame_timeout_s));
        return;
      }
      tick();
    }
  }

  void finish_loop() {
    loop_.finish();
    while (!ended_ && loop_.tick()) {
    }
    ended_ = true;
    result_.ticks = loop_.result().ticks;
    result_.overruns = loop_.stats().overruns;
    if (ok() && loop_.result().fault_detected)
      note_loop_end();
  }

  runtime::ControlLoop& loop_;
  const plant::Twin* twin_;
  camera::Camera& camera_;
  const SequenceParams& p_;
  const rig::Progress& progress_;
  double period_s_;
  std::size_t total_;
  SettleWindow window_;
  camera::PlatePose origin_{};
  Clock::time_point start_wall_ = Clock::now();
  double start_loop_s_ = 0.0;
  bool ended_ = false;
  // TriggerMode::kLine: edges forwarded to the camera, the last one's time, the pose it starts.
  std::uint64_t edges_forwarded_ = 0;
  double last_edge_s_ = 0.0;
  camera::PlatePose edge_pose_{};
  std::optional<FringeLockSession> lock_;
  bool holding_ = false;         // the hold's frames are coming (hold())
  std::size_t hold_frames_ = 0;  // ... of which arrived
  SequenceResult result_;
  // Last, so that it is gone (its job done) before what its jobs touch: lock_, result_.
  std::optional<FitThread> fit_thread_;  // the lock on a real-time clock
};

}  // namespace

std::string take_frame(camera::FrameStatus s, camera::Frame& f, const camera::Camera& camera,
                       double arrival_wall_s, SequenceResult& result) {
  if (s == camera::FrameStatus::kLost)
    return fmt::format("camera {} lost frame {}", camera.name(), f.frame_id);
  if (s != camera::FrameStatus::kOk)
    return fmt::format("camera {}: {} ({})", camera.name(), camera::to_string(s), camera.message());
  const std::size_t k = result.frames.size();
  if (k >= result.exposures.size())
    return fmt::format("camera {} delivered frame {} that no trigger asked for", camera.name(),
                       f.frame_id);
  result.exposures[k].frame_id = f.frame_id;
  result.exposures[k].arrival_wall_s = arrival_wall_s;
  result.frames.push_back(std::move(f));
  return {};
}

double step_piston_nm(const SequenceParams& p, std::size_t k) {
  return p.steps_rad[k] * p.wavelength_nm / (4.0 * std::numbers::pi);
}

ExposureRecord planned_exposure(const SequenceParams& p, std::size_t index, double move_time_s) {
  const std::size_t n = p.steps_rad.size();
  ExposureRecord rec;
  rec.average = static_cast<int>(index / n);
  rec.frame = static_cast<int>(index % n);
  rec.commanded_step_rad = p.steps_rad[index % n];
  rec.commanded_piston_nm = step_piston_nm(p, index % n);
  rec.move_time_s = move_time_s;
  return rec;
}

double sequence_floor_s(const SequenceParams& p, std::size_t hold_ticks, double period_s,
                        const camera::CameraSettings& settings) {
  const double frames = static_cast<double>(p.averages) * static_cast<double>(p.steps_rad.size());
  return frames *
         (static_cast<double>(hold_ticks) * period_s + settings.exposure_s + settings.readout_s);
}

const char* to_string(TriggerMode mode) noexcept {
  return mode == TriggerMode::kLine ? "line" : "software";
}

std::vector<double> commanded_steps(psi::Algorithm a, const std::vector<double>& given,
                                    std::string_view option) {
  const bool free_steps = a == psi::Algorithm::kLeastSquares || a == psi::Algorithm::kAia ||
                          a == psi::Algorithm::kTiltAia;
  if (!given.empty() && !free_steps)
    throw core::InputError(
        fmt::format("{}: {} has fixed steps; unequal steps need lsq, aia or "
                    "tilt-aia",
                    option, psi::algorithm_name(a)));
  const int need = psi::required_frames(a);
  std::vector<double> steps = given;
  for (int k = 0; given.empty() && k < (need > 0 ? need : 5); ++k)
    steps.push_back(k * psi::nominal_step_rad(a));
  if (need > 0 && static_cast<std::size_t>(need) != steps.size())
    throw core::InputError(fmt::format("--algorithm {} needs {} frames, {} given",
                                       psi::algorithm_name(a), need, steps.size()));
  return steps;
}

std::string travel_problem(const SequenceParams& p, std::optional<double> travel_z_max_um,
                           std::string_view calibration_source) {
  double top_nm = 0.0;
  for (std::size_t k = 0; k < p.steps_rad.size(); ++k)
    top_nm = std::max(top_nm, step_piston_nm(p, k));
  const double top_um = p.base_um + top_nm * 1e-3;
  if (!travel_z_max_um || top_um <= *travel_z_max_um)
    return {};
  return fmt::format(
      "base {} um: the sequence reaches {:.4f} um, beyond the calibrated travel {} "
      "um ({})",
      p.base_um, top_um, *travel_z_max_um, calibration_source);
}

std::string sequence_problem(const SequenceParams& p) {
  const std::size_t n = p.steps_rad.size();
  if (n < 3 || n > 64)
    return fmt::format("{} steps: a measurement takes 3 to 64 frames", n);
  for (std::size_t k = 0; k < n; ++k)
    if (!std::isfinite(p.steps_rad[k]) || std::fabs(p.steps_rad[k]) > 8.0 * std::numbers::pi)
      return fmt::format("step {} = {} rad: must be finite, within +-8 pi", k, p.steps_rad[k]);
  if (p.steps_rad[0] != 0.0)
    return fmt::format("step 0 = {} rad: the first frame is the reference, 0", p.steps_rad[0]);
  if (!(p.wavelength_nm >= 200.0 && p.wavelength_nm <= 2000.0))
    return fmt::format("wavelength {} nm: must be in [200, 2000]", p.wavelength_nm);
  if (!(p.base_um >= 0.0 && p.base_um <= 1000.0))
    return fmt::format("base {} um: must be in [0, 1000]", p.base_um);
  if (!(p.initial_settle_s >= 0.0 && p.initial_settle_s <= 60.0))
    return fmt::format("initial settle {} s: must be in [0, 60]", p.initial_settle_s);
  if (!(p.on_target.band_nm > 0.0 && p.on_target.band_nm <= 1000.0))
    return fmt::format("settle band {} nm: must be in (0, 1000]", p.on_target.band_nm);
  if (!(p.on_target.hold_s >= 0.0 && p.on_target.hold_s <= 10.0))
    return fmt::format("settle hold {} s: must be in [0, 10]", p.on_target.hold_s);
  if (!(p.on_target.timeout_s > 0.0 && p.on_target.timeout_s <= 60.0))
    return fmt::format("settle timeout {} s: must be in (0, 60]", p.on_target.timeout_s);
  if (p.averages < kMinAverages || p.averages > kMaxAverages)
    return fmt::format("{} averages: must be {} to {}", p.averages, kMinAverages, kMaxAverages);
  if (!(p.frame_timeout_s > 0.0 && p.frame_timeout_s <= 600.0))
    return fmt::format("frame timeout {} s: must be in (0, 600]", p.frame_timeout_s);
  if (!(p.hold_s >= 0.0 && p.hold_s <= 3600.0))
    return fmt::format("hold {} s: must be in [0, 3600]", p.hold_s);
  return {};
}

std::vector<double> path_errors_nm(const SequenceResult& result,
                                   const std::vector<ExposureRecord>& records) {
  std::vector<double> d;
  if (result.exposures.empty() || !result.exposures.front().has_truth)
    return d;
  const ExposureRecord& e0 = result.exposures.front();
  const double offset_nm = e0.truth_piston_nm - e0.commanded_piston_nm;
  for (const ExposureRecord& e : records) {
    if (!e.has_truth)
      return {};
    d.push_back(e.truth_piston_nm - e.commanded_piston_nm - offset_nm);
  }
  return d;
}

namespace {

std::optional<double> rms_from(const std::vector<double>& d, std::size_t first) {
  if (first >= d.size())
    return std::nullopt;
  double sum = 0.0;
  for (std::size_t i = first; i < d.size(); ++i)
    sum += d[i] * d[i];
  return std::sqrt(sum / static_cast<double>(d.size() - first));
}

}  // namespace

std::optional<double> path_error_rms_nm(const SequenceResult& result, std::size_t first) {
  return rms_from(path_errors_nm(result, result.exposures), first);
}

SequenceResult run_sequence(runtime::ControlLoop& loop, const plant::Twin* twin,
                            camera::Camera& camera, const SequenceParams& params,
                            const rig::Progress& progress) {
  if (const std::string why = sequence_problem(params); !why.empty())
    throw core::InputError("measurement: " + why);
  if (params.trigger == TriggerMode::kLine && !loop.daq().has_trigger_line())
    throw core::InputError(
        fmt::format("measurement: trigger line: DAQ {} has no trigger line", loop.daq().name()));
  return Runner(loop, twin, camera, params, progress).run();
}

}  // namespace piezoshift::instrument
