#pragma once
// The twin camera (`twin`): the Fizeau simulation (psi/fizeau_simulation.hpp) as a camera, fed
// the twin's true plate motion by the measurement through observe_plate().
//
//   trigger(t)           refused unless started, t >= the previous trigger's t + exposure_s +
//                        readout_s (loop time, 1 ns slack), and a buffer is free (every one
//                        holding a frame not yet polled refuses it, never drops it)
//   observe_plate(pose)  once per loop tick: a pose with t <= time_s <= t + exposure_s (1 ns
//                        slack) is kept in the exposure's preallocated buffer (exposure_s x
//                        max_tick_rate_Hz + 2 poses); the first pose at or past t + exposure_s
//                        completes the exposure, which is handed to the worker thread (so is an
//                        unfinished exposure when the next trigger comes)
//   worker thread        (a frame triggered in the scene's fringe loss: visibility 0)
//                        frame k = psi::render_frame(surface, mask, fizeau, sensor, poses,
//                        Rng(frame_seed(seed, k))), then counts x 10^(gain_dB / 20), rounded and
//                        clipped to 2^bits - 1 (bits of the pixel format); an exposure that saw
//                        no pose, or more than the buffer holds, is a kError frame, never blank
//   poll()/wait()        frames in trigger order, ids 0, 1, 2, ...; trigger_time_s = t,
//                        device_timestamp_ns = t in ns, system_timestamp_ns = CLOCK_MONOTONIC
//                        when the frame was rendered
//
// Threads: trigger() and observe_plate() from one thread (the loop's: no allocation, no lock, no
// system call), poll() and wait() from one thread (it may be the same). Buffers travel between
// the three through lock-free rings (runtime/spsc_ring.hpp) as indices; a frame's counts are
// swapped into the caller's Frame, so poll() copies no pixels and allocates nothing.
// The noise of frame k depends on (seed, k) alone, so a seed gives the same frames whatever the
// threads' timing. TriggerSource::kLine is taken as well: the twin's line is the sim backend's
// trigger wire (sim_backend.hpp), whose rising edges the measurement hands to trigger(t_edge), so
// trigger() is the line's edge arriving; its rules above are the same.
#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "piezoshift/camera/camera.hpp"
#include "piezoshift/psi/fizeau_simulation.hpp"
#include "piezoshift/psi/grid.hpp"
#include "piezoshift/runtime/spsc_ring.hpp"

namespace piezoshift::camera {

//! The tick rate the pose buffers are sized for: the loop runs at 1 to 10 kHz.
inline constexpr double kTwinMaxTickRate_Hz = 20000.0;

//! The seed of frame k's noise: a 64-bit mix (splitmix64) of seed and k.
std::uint64_t frame_seed(std::uint64_t seed, std::uint64_t frame_id) noexcept;

//! What the twin camera looks at: the test surface behind the Fizeau's optics.
struct TwinScene {
  psi::Map surface_nm;  //!< NaN outside the mask
  psi::Mask mask;
  psi::FizeauParams fizeau;
  std::uint64_t seed = 1;
  double max_tick_rate_Hz = kTwinMaxTickRate_Hz;
  //! Frames triggered in [fringe_loss_start_s, + fringe_loss_s) are rendered without fringes
  //! (visibility 0: CameraConfig's fringe loss); a negative start: never.
  double fringe_loss_start_s = -1.0;
  double fringe_loss_s = 0.0;
};

//! The scene `psi simulate` renders for the same surface, optics and seed: the centred disk of
//! fizeau.pupil_radius_px as the mask, the surface drawn from plant::Rng(seed) (so a
//! measurement's truth equals psi simulate's), and seed for the frames' noise. Throws
//! core::InputError for optics out of range (psi::fizeau_problem).
TwinScene make_twin_scene(const psi::SurfaceSpec& surface, const psi::FizeauParams& fizeau,
                          std::uint64_t seed);

//! Frame frame_id of the scene seen from poses, as the twin camera counts it: psi::render_frame
//! with the frame's noise draws (frame_seed(scene.seed, frame_id)), then the digital gain after
//! quantisation (0 dB leaves the counts as they are), rounded and clipped to 2^bit_depth - 1.
//! The twin camera's frames and the floor of a measurement (instrument/twin_floor.hpp) both.
void render_twin_counts(const TwinScene& scene, const psi::CameraParams& sensor, double gain_dB,
                        std::span<const psi::PoseSample> poses, std::uint64_t frame_id,
                        std::vector<std::uint16_t>& counts);

//! The optics a measurement renders a camera's frames with: the frame's size, a pupil of 0.47 of
//! its shorter side (`psi simulate`'s proportion) and pupil_radius_m on the plate
//! (CameraConfig::pupil_radius_m), wavelength_nm; the rest psi's defaults.
psi::FizeauParams measurement_optics(const CameraSettings& settings, double pupil_radius_m,
                                     double wavelength_nm);

class TwinCamera final : public Camera {
 public:
  //! sensor: exposure_s and bit_depth are replaced by configure()'s settings. Throws
  //! core::InputError when the scene's sizes disagree or a parameter is out of range.
  TwinCamera(TwinScene scene, const psi::CameraParams& sensor);
  ~TwinCamera() override;

  //! Refuses (core::InputError naming the setting) a size other than the scene's and any value
  //! outside camera_settings_problem()'s ranges. Allocates the buffers.
  void configure(const CameraSettings& settings) override;
  //! Starts the worker; frame ids restart at 0.
  void start() override;
  bool trigger(double loop_time_s) noexcept override;
  FrameStatus poll(Frame& frame) noexcept override;
  FrameStatus wait(Frame& frame, double timeout_s) override;
  //! Joins the worker; frames not yet polled and an exposure under way are discarded.
  void stop() noexcept override;
  void observe_plate(const PlatePose& pose) noexcept override;

  std::string name() const override { return "twin"; }
  const CameraSettings& settings() const override { return settings_; }
  std::string message() const override;
  std::uint64_t lost_frames() const noexcept override { return 0; }

  //! Poses one exposure's buffer holds (exposure_s x max_tick_rate_Hz + 2).
  std::size_t pose_capacity() const noexcept { return pose_capacity_; }

 private:
  struct Slot;
  struct Job {
    std::uint32_t slot = 0;
  };
  enum class Refusal : std::uint8_t { kNone, kNotStarted, kTime, kBusy, kNoBuffer };

  void finish_exposure() noexcept;
  void worker_loop() noexcept;
  void render(Slot& slot) noexcept;

  TwinScene scene_;
  psi::CameraParams sensor_;
  CameraSettings settings_;
  bool configured_ = false;
  std::size_t pose_capacity_ = 0;

  std::vector<std::unique_ptr<Slot>> slots_;
  std::unique_ptr<runtime::SpscRing<Job>> jobs_;  // loop -> worker: exposures to render
  std::unique_ptr<runtime::SpscRing<Job>> done_;  // worker -> consumer: frames rendered
  std::unique_ptr<runtime::SpscRing<Job>> free_;  // consumer -> loop: buffers polled
  std::thread worker_;
  std::atomic<bool> running_{false};

  // The loop's side (trigger, observe_plate).
  Slot* exposing_ = nullptr;  // the exposure collecting poses, if any
  std::uint64_t next_id_ = 0;
  double busy_until_s_ = 0.0;  // previous trigger + exposure + readout
  bool any_trigger_ = false;
  std::atomic<Refusal> refusal_{Refusal::kNone};
  std::atomic<double> refused_at_s_{0.0};

  // The consumer's side (poll, wait).
  std::string frame_error_;
  std::atomic<bool> last_was_frame_error_{false};
};

}  // namespace piezoshift::camera
