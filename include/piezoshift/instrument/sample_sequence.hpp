#pragma once
// The phase-shifting sequence of sequence.hpp driven from a running loop's HostSamples, for a
// loop the caller does not own (`serve`'s: its ticks are the loop thread's, its moves go through
// GCS). The caller hands every sample, in tick order, to feed() on one host thread, and calls
// poll() between batches; nothing here touches the loop's thread.
//
//   move(base_um) (the caller's MOV of P1..P3); wait until a sample shows Z_d applied;
//   hold initial_settle_s of loop time; settle (settle_window.hpp on S - feedback)
//   for each average a, each frame k:
//     move(base_um + piston_k), piston_k = steps_rad[k] lambda / (4 pi); wait until applied
//     settle; not settled within timeout_s is a failure
//     camera.trigger(t) at the loop time of the sample that settled (or the first after it that
//     the camera takes); the exposure's ticks' poses to the camera and to the record
//     (exposure_accumulator.hpp)
//   every frame arrived within frame_timeout_s (wall) of the last exposure: done
//
// Every sample's plate pose, relative to the pose at the settled base, goes to the camera
// (observe_plate; the twin camera renders from it). It does not start on a latched fault (its
// first move would clear it: the operator's to do). The sequence fails, with the first reason,
// when a move is refused, the supervisor latches a fault, the servo goes off, the loop's Z_d
// departs from what the sequence commanded (another client moved the stage, a wave generator, a
// stop), a step does not settle, or a frame is lost or late. The stage stays where the last step
// put it (the caller's loop keeps running).
#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <string>

#include "piezoshift/camera/camera.hpp"
#include "piezoshift/instrument/exposure_accumulator.hpp"
#include "piezoshift/instrument/sequence.hpp"
#include "piezoshift/instrument/settle_window.hpp"

namespace piezoshift::instrument {

//! What the sequence reads of one loop tick (from runtime::HostSample).
struct LoopSample {
  std::uint64_t tick = 0;
  double t_s = 0.0;                        //!< loop time
  std::array<double, 3> gauge_error_nm{};  //!< S - feedback per channel (closed loop)
  std::array<double, 3> zd_um{};           //!< Z_d of P1..P3 in force
  bool closed_loop = false;
  bool overrun = false;
  bool faulted = false;
  std::string fault;  //!< the latched fault's name, when faulted
  bool has_truth = false;
  camera::PlatePose pose{};  //!< the plate's true pose (has_truth), absolute
};

class SampleSequence {
 public:
  //! Commands Z_d = z_um on P1..P3: "" when the loop was sent it, else why it was refused.
  using Move = std::function<std::string(double z_um)>;

  //! The camera must be started and hold no frame. Throws core::InputError for parameters
  //! sequence_problem() refuses.
  SampleSequence(camera::Camera& camera, const SequenceParams& params, double period_s, Move move);

  //! One sample, in tick order.
  void feed(const LoopSample& s);
  //! Frames that have arrived; the wall-clock timeout of the last frames.
  void poll();
  bool done() const noexcept { return phase_ == Phase::kDone; }
  //! Frames taken and frames in all, for progress.
  std::size_t frames_taken() const noexcept { return result_.exposures.size(); }
  std::size_t frames_total() const noexcept { return total_; }
  //! The result once done().
  SequenceResult take() { return std::move(result_); }

 private:
  enum class Phase { kStart, kApply, kHold, kSettle, kTrigger, kExpose, kCollect, kDone };
  using Clock = std::chrono::steady_clock;

  void fail(const std::string& why);
  void command(double z_um);
  bool watch(const LoopSample& s);
  std::string moved_away(const LoopSample& s) const;
  void on_settled(const LoopSample& s);
  void next_frame(const LoopSample& s);
  void finish_exposure(const LoopSample& s);
  camera::PlatePose relative(const LoopSample& s) const;

  camera::Camera& camera_;
  SequenceParams p_;
  double period_s_;
  Move move_;
  std::size_t total_;
  SettleWindow window_;
  ExposureAccumulator exposure_;
  std::size_t exposure_ticks_;
  Phase phase_ = Phase::kStart;
  bool based_ = false;  //!< the base has settled: frames from here on
  double target_um_ = 0.0;
  double previous_um_ = 0.0;   //!< the target before target_um_ (has_previous_)
  bool has_previous_ = false;  //!< false for the first move: the stage was anywhere before it
  bool applied_ = false;
  double phase_t0_s_ = 0.0;
  std::uint64_t last_tick_ = 0;
  bool have_tick_ = false;
  std::size_t next_ = 0;  //!< the next frame, over averages x steps
  ExposureRecord rec_{};
  camera::PlatePose origin_{};
  double start_loop_s_ = 0.0;
  double last_t_s_ = 0.0;
  Clock::time_point start_wall_ = Clock::now();
  Clock::time_point collect_from_ = Clock::now();
  SequenceResult result_;
};

}  // namespace piezoshift::instrument
