#include "piezoshift/camera/twin_camera.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <exception>
#include <span>
#include <utility>

#include <fmt/core.h>

#include "piezoshift/camera/camera_config.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/plant/random.hpp"

namespace piezoshift::camera {

namespace {

// Loop times are sums of tick periods: a nanosecond of slack keeps an exact tick on the right
// side of an exposure's or a readout's end.
constexpr double kSlack_s = 1e-9;

std::size_t ring_capacity(std::size_t n) {
  std::size_t c = 2;
  while (c < n)
    c *= 2;
  return c;
}

std::int64_t monotonic_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

}  // namespace

// One buffer: the poses of an exposure (loop thread), then its frame (worker), then the frame's
// delivery (consumer). Owned by one thread at a time; the rings hand it over.
struct TwinCamera::Slot {
  std::uint32_t index = 0;
  std::vector<psi::PoseSample> poses;  // pose_capacity_ entries, n_poses used
  std::size_t n_poses = 0;
  bool overflow = false;
  std::uint64_t frame_id = 0;
  double trigger_time_s = 0.0;
  double end_s = 0.0;
  std::vector<std::uint16_t> counts;
  FrameStatus status = FrameStatus::kOk;
  std::string error;
  std::int64_t system_timestamp_ns = 0;
};

void render_twin_counts(const TwinScene& scene, const psi::CameraParams& sensor, double gain_dB,
                        std::span<const psi::PoseSample> poses, std::uint64_t frame_id,
                        std::vector<std::uint16_t>& counts) {
  plant::Rng rng(frame_seed(scene.seed, frame_id));
  const psi::Map m =
      psi::render_frame(scene.surface_nm, scene.mask, scene.fizeau, sensor, poses, rng);
  // Gain after quantisation, as a digital gain.
  const double gain = std::pow(10.0, gain_dB / 20.0);
  const double top = std::ldexp(1.0, sensor.bit_depth) - 1.0;
  counts.resize(m.size());
  for (std::size_t p = 0; p < m.size(); ++p)
    counts[p] = static_cast<std::uint16_t>(std::min(top, std::round(m.v[p] * gain)));
}

std::uint64_t frame_seed(std::uint64_t seed, std::uint64_t frame_id) noexcept {
  // splitmix64 of the seed, then of that xor the frame id: neighbouring seeds and ids give
  // unrelated streams
  auto mix = [](std::uint64_t z) {
    z += 0x9e3779b97f4a7c15ULL;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  };
  return mix(mix(seed) ^ frame_id);
}

TwinScene make_twin_scene(const psi::SurfaceSpec& surface, const psi::FizeauParams& fizeau,
                          std::uint64_t seed) {
  if (std::string p = psi::fizeau_problem(fizeau); !p.empty())
    throw core::InputError("twin camera: " + p);
  TwinScene s;
  s.fizeau = fizeau;
  s.mask = psi::disk_mask(fizeau.width_px, fizeau.height_px, fizeau.pupil_radius_px);
  plant::Rng rng(seed);  // psi/simulation.cpp draws the truth the same way
  s.surface_nm = psi::make_surface_nm(surface, s.mask, rng);
  s.seed = seed;
  return s;
}

psi::FizeauParams measurement_optics(const CameraSettings& settings, double pupil_radius_m,
                                     double wavelength_nm) {
  psi::FizeauParams fizeau;
  fizeau.pupil_radius_m = pupil_radius_m;
  fizeau.width_px = settings.width_px;
  fizeau.height_px = settings.height_px;
  fizeau.pupil_radius_px = 0.47 * std::min(settings.width_px, settings.height_px);
  fizeau.wavelength_nm = wavelength_nm;
  return fizeau;
}

TwinCamera::TwinCamera(TwinScene scene, const psi::CameraParams& sensor)
    : scene_(std::move(scene)), sensor_(sensor) {
  const psi::FizeauParams& f = scene_.fizeau;
  if (std::string p = psi::fizeau_problem(f); !p.empty())
    throw core::InputError("twin camera: " + p);
  if (std::string p = psi::camera_problem(sensor_); !p.empty())
    throw core::InputError("twin camera: " + p);
  const std::size_t pixels = static_cast<std::size_t>(f.width_px) * f.height_px;
  if (scene_.surface_nm.width != f.width_px || scene_.surface_nm.height != f.height_px ||
      scene_.surface_nm.size() != pixels || scene_.mask.width != f.width_px ||
      scene_.mask.height != f.height_px || scene_.mask.size() != pixels)
    throw core::InputError(fmt::format(
        "twin camera: the surface ({} x {}) and mask ({} x {}) must be the Fizeau grid's {} x {}",
        scene_.surface_nm.width, scene_.surface_nm.height, scene_.mask.width, scene_.mask.height,
        f.width_px, f.height_px));
  if (!(scene_.max_tick_rate_Hz >= 1.0 && scene_.max_tick_rate_Hz <= 1e5))
    throw core::InputError(fmt::format("twin camera: max_tick_rate_Hz = {} must be in [1, 1e5]",
                                       scene_.max_tick_rate_Hz));
}

TwinCamera::~TwinCamera() {
  stop();
}

void TwinCamera::configure(const CameraSettings& s) {
  stop();
  if (std::string p = camera_settings_problem(s); !p.empty())
    throw core::InputError("twin camera: " + p);
  const psi::FizeauParams& f = scene_.fizeau;
  if (s.width_px != f.width_px || s.height_px != f.height_px)
    throw core::InputError(
        fmt::format("twin camera: camera.width_px x height_px = {} x {}, but the simulated "
                    "interferometer's grid is {} x {}",
                    s.width_px, s.height_px, f.width_px, f.height_px));
  sensor_.exposure_s = s.exposure_s;
  sensor_.bit_depth = bit_depth(s.format);
  if (std::string p = psi::camera_problem(sensor_); !p.empty())
    throw core::InputError("twin camera: " + p);
  settings_ = s;
  pose_capacity_ = static_cast<std::size_t>(std::ceil(s.exposure_s * scene_.max_tick_rate_Hz)) + 2;
  slots_.clear();
  for (int k = 0; k < s.buffer_count; ++k) {
    auto slot = std::make_unique<Slot>();
    slot->index = static_cast<std::uint32_t>(k);
    slot->poses.resize(pose_capacity_);
    slot->counts.resize(static_cast<std::size_t>(s.width_px) * s.height_px);
    slot->error.reserve(256);
    slots_.push_back(std::move(slot));
  }
  configured_ = true;
}

void TwinCamera::start() {
  if (!configured_)
    throw core::InputError("twin camera: start() before configure()");
  stop();
  const std::size_t capacity = ring_capacity(slots_.size());
  jobs_ = std::make_unique<runtime::SpscRing<Job>>(capacity);
  done_ = std::make_unique<runtime::SpscRing<Job>>(capacity);
  free_ = std::make_unique<runtime::SpscRing<Job>>(capacity);
  for (const auto& slot : slots_)
    free_->try_push(Job{slot->index});
  exposing_ = nullptr;
  next_id_ = 0;
  busy_until_s_ = 0.0;
  any_trigger_ = false;
  refusal_ = Refusal::kNone;
  last_was_frame_error_ = false;
  frame_error_.clear();
  running_.store(true, std::memory_order_release);
  worker_ = std::thread([this] { worker_loop(); });
}

void TwinCamera::stop() noexcept {
  running_.store(false, std::memory_order_release);
  if (worker_.joinable())
    worker_.join();
  exposing_ = nullptr;
}

bool TwinCamera::trigger(double t) noexcept {
  auto refuse = [&](Refusal why) {
    refused_at_s_.store(t, std::memory_order_relaxed);
    refusal_.store(why, std::memory_order_release);
    last_was_frame_error_.store(false, std::memory_order_release);
    return false;
  };
  if (!running_.load(std::memory_order_acquire))
    return refuse(Refusal::kNotStarted);
  if (!std::isfinite(t))
    return refuse(Refusal::kTime);
  if (any_trigger_ && t < busy_until_s_ - kSlack_s)
    return refuse(Refusal::kBusy);
  if (exposing_ != nullptr)
    finish_exposure();  // t is past its end: no pose came after it
  Job free{};
  if (!free_->try_pop(free))
    return refuse(Refusal::kNoBuffer);
  Slot& s = *slots_[free.slot];
  s.frame_id = next_id_++;
  s.trigger_time_s = t;
  s.end_s = t + settings_.exposure_s;
  s.n_poses = 0;
  s.overflow = false;
  exposing_ = &s;
  busy_until_s_ = s.end_s + settings_.readout_s;
  any_trigger_ = true;
  return true;
}

void TwinCamera::observe_plate(const PlatePose& pose) noexcept {
  if (exposing_ == nullptr)
    return;
  Slot& s = *exposing_;
  if (pose.time_s < s.trigger_time_s - kSlack_s)
    return;
  if (pose.time_s <= s.end_s + kSlack_s) {
    if (s.n_poses < s.poses.size())
      s.poses[s.n_poses++] = {pose.time_s, pose.piston_nm, pose.theta_x_urad, pose.theta_y_urad};
    else
      s.overflow = true;
  }
  if (pose.time_s >= s.end_s - kSlack_s)
    finish_exposure();
}

void TwinCamera::finish_exposure() noexcept {
  // Never full: at most buffer_count indices circulate through rings of at least that capacity.
  jobs_->try_push(Job{exposing_->index});
  exposing_ = nullptr;
}

void TwinCamera::worker_loop() noexcept {
  while (running_.load(std::memory_order_acquire)) {
    Job job{};
    if (!jobs_->try_pop(job)) {
      std::this_thread::sleep_for(std::chrono::microseconds(200));
      continue;
    }
    render(*slots_[job.slot]);
    done_->try_push(job);
  }
}

void TwinCamera::render(Slot& s) noexcept {
  s.status = FrameStatus::kError;
  try {
    if (s.n_poses == 0) {
      s.error = fmt::format(
          "twin camera: frame {} saw no plate pose during its exposure [{}, {}] s (observe_plate "
          "must be called at least once within each exposure: ticks further apart than "
          "exposure_s = {} s?)",
          s.frame_id, s.trigger_time_s, s.end_s, settings_.exposure_s);
    } else if (s.overflow) {
      s.error = fmt::format(
          "twin camera: frame {} saw more than {} plate poses during its {} s exposure (the "
          "buffer holds exposure_s x {} Hz + 2): ticks faster than the twin camera allows",
          s.frame_id, pose_capacity_, settings_.exposure_s, scene_.max_tick_rate_Hz);
    } else {
      psi::CameraParams sensor = sensor_;
      if (scene_.fringe_loss_start_s >= 0.0 && s.trigger_time_s >= scene_.fringe_loss_start_s &&
          s.trigger_time_s < scene_.fringe_loss_start_s + scene_.fringe_loss_s)
        sensor.visibility = 0.0;
      render_twin_counts(scene_, sensor, settings_.gain_dB,
                         std::span<const psi::PoseSample>(s.poses.data(), s.n_poses), s.frame_id,
                         s.counts);
      s.status = FrameStatus::kOk;
    }
  } catch (const std::exception& e) {
    s.error = fmt::format("twin camera: frame {}: {}", s.frame_id, e.what());
  }
  s.system_timestamp_ns = monotonic_ns();
}

FrameStatus TwinCamera::poll(Frame& frame) noexcept {
  if (!running_.load(std::memory_order_acquire))
    return FrameStatus::kNone;
  Job job{};
  if (!done_->try_pop(job))
    return FrameStatus::kNone;
  Slot& s = *slots_[job.slot];
  frame.frame_id = s.frame_id;
  frame.width_px = settings_.width_px;
  frame.height_px = settings_.height_px;
  frame.format = settings_.format;
  frame.exposure_s = settings_.exposure_s;
  frame.trigger_time_s = s.trigger_time_s;
  frame.device_timestamp_ns = std::llround(s.trigger_time_s * 1e9);
  frame.system_timestamp_ns = s.system_timestamp_ns;
  const FrameStatus status = s.status;
  if (status == FrameStatus::kOk) {
    std::swap(frame.counts, s.counts);  // the worker resizes what it gets back
  } else {
    frame.counts.clear();  // no stale image behind an error (keeps the capacity)
    std::swap(frame_error_, s.error);
    last_was_frame_error_.store(true, std::memory_order_release);
  }
  free_->try_push(job);
  return status;
}

FrameStatus TwinCamera::wait(Frame& frame, double timeout_s) {
  if (!running_.load(std::memory_order_acquire)) {
    frame_error_ = "twin camera: wait() while not started";
    last_was_frame_error_ = true;
    return FrameStatus::kError;
  }
  return poll_until(*this, frame, timeout_s);
}

std::string TwinCamera::message() const {
  if (last_was_frame_error_.load(std::memory_order_acquire))
    return frame_error_;
  const double t = refused_at_s_.load(std::memory_order_relaxed);
  switch (refusal_.load(std::memory_order_acquire)) {
    case Refusal::kNone:
      return {};
    case Refusal::kNotStarted:
      return fmt::format("twin camera: trigger at t = {} s refused: not started", t);
    case Refusal::kTime:
      return fmt::format("twin camera: trigger at t = {} s refused: not a finite time", t);
    case Refusal::kBusy:
      return fmt::format(
          "twin camera: trigger at t = {} s refused: the previous exposure ({} s) and its "
          "readout ({} s) are not over",
          t, settings_.exposure_s, settings_.readout_s);
    case Refusal::kNoBuffer:
      return fmt::format(
          "twin camera: trigger at t = {} s refused: all {} buffers hold frames not yet polled", t,
          settings_.buffer_count);
  }
  return {};
}

}  // namespace piezoshift::camera
