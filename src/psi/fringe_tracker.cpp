#include "piezoshift/psi/fringe_tracker.hpp"

#include <cmath>
#include <complex>
#include <limits>
#include <stdexcept>

#include <fmt/core.h>
#include <Eigen/Dense>

#include "piezoshift/core/input_error.hpp"

namespace piezoshift::psi {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// The least coherence of a window's phase with the reference (|mean exp(i r)|, 1 for a perfect
// match, about 0 for an unrelated phase), and the least margin between the two signs' coherences.
constexpr double kMinCoherence = 0.5;
constexpr double kMinSignMargin = 0.1;

double wrap(double a) {
  return std::remainder(a, 2.0 * kPi);
}

}  // namespace

std::string fringe_tracker_problem(const FringeTrackerParams& p) {
  if (p.window_frames < 3 || p.window_frames > 64)
    return fmt::format("window_frames = {}: must be in 3..64", p.window_frames);
  if (p.hop_frames < 0 || p.hop_frames > p.window_frames - 1)
    return fmt::format("hop_frames = {}: must be in 1..window_frames - 1 ({}), or 0 for that",
                       p.hop_frames, p.window_frames - 1);
  if (!(p.wavelength_nm >= 100.0 && p.wavelength_nm <= 20000.0))
    return fmt::format("wavelength_nm = {}: must be in 100..20000", p.wavelength_nm);
  if (!(p.plate_m_per_px > 0.0 && p.plate_m_per_px < 0.01))
    return fmt::format("plate_m_per_px = {}: must be in (0, 0.01)", p.plate_m_per_px);
  if (p.first_direction != 1 && p.first_direction != -1)
    return fmt::format("first_direction = {}: must be +1 or -1", p.first_direction);
  if (!(p.max_step_rad > 0.0 && p.max_step_rad < kPi))
    return fmt::format("max_step_rad = {}: must be in (0, pi): a step of pi is a quarter wave",
                       p.max_step_rad);
  if (!(p.max_step_change_rad > 0.0))
    return fmt::format("max_step_change_rad = {}: must be > 0", p.max_step_change_rad);
  if (!(p.max_noise_to_modulation > 0.0))
    return fmt::format("max_noise_to_modulation = {}: must be > 0", p.max_noise_to_modulation);
  return {};
}

FringeTracker::FringeTracker(const Mask& mask, const FringeTrackerParams& params)
    : mask_(mask), p_(params), tripod_(params.points) {
  if (const std::string why = fringe_tracker_problem(p_); !why.empty())
    throw core::InputError("fringe tracker: " + why);
  if (p_.hop_frames == 0)
    p_.hop_frames = p_.window_frames - 1;
  const Pupil pupil = pupil_of(mask_);  // throws for an empty mask
  pupil_radius_m_ = pupil.radius_px * p_.plate_m_per_px;
  ref_ = phase_reference(mask_);
}

std::vector<FringePose> FringeTracker::push(const Map& frame) {
  if (frame.width != mask_.width || frame.height != mask_.height || frame.size() != mask_.size())
    throw std::invalid_argument(
        fmt::format("fringe tracker: frame {} is {} x {} px, the pupil's mask {} x {}", seen_,
                    frame.width, frame.height, mask_.width, mask_.height));
  ++seen_;
  if (!lost_.empty())
    return refuse_from(seen_ - 1, lost_);
  if (p_.method == FringeMethod::kReference && have_phase_)
    return track_frame(frame);
  window_.push_back(frame);
  const auto nw = static_cast<std::size_t>(p_.window_frames);
  if (window_.size() > nw)
    window_.pop_front();
  if (seen_ < nw || (seen_ - nw) % static_cast<std::size_t>(p_.hop_frames) != 0)
    return {};
  return process_window();
}

std::vector<FringePose> FringeTracker::refuse_from(std::size_t first, const std::string& reason) {
  if (lost_.empty())
    lost_ = fmt::format("fringe order lost at frame {}: {}", first, reason);
  std::vector<FringePose> out;
  for (std::size_t f = std::max(first, next_); f < seen_; ++f) {
    FringePose r;
    r.frame = f;
    r.reason = f == first ? reason : lost_;
    r.piston_nm = r.theta_x_urad = r.theta_y_urad = r.noise_to_modulation = kNaN;
    r.points_um = {kNaN, kNaN, kNaN};
    out.push_back(std::move(r));
  }
  next_ = seen_;
  return out;
}

// The window's first frame's plane, corrected against the reference phase, and the sign of the
// window's phase (see the header); a reason when the window does not match the reference.
std::string FringeTracker::anchor(const PhaseResult& r, int& sigma, Plane& w0) const {
  using cd = std::complex<double>;
  std::array<cd, 2> mean{};
  std::size_t n = 0;
  for (std::size_t q = 0; q < ref_.pixels.size(); ++q) {
    const double phi = r.phase_rad.v[ref_.pixels[q]];
    if (!std::isfinite(phi))
      continue;
    const double known =
        w0.piston_rad + w0.tip_rad * ref_.y[q] + w0.tilt_rad * ref_.x[q] + ref_.phase_rad[q];
    mean[0] += std::polar(1.0, phi - known);
    mean[1] += std::polar(1.0, -phi - known);
    ++n;
  }
  if (n < 3)
    return "no pupil pixel has fringes";
  const double c_plus = std::abs(mean[0]) / static_cast<double>(n);
  const double c_minus = std::abs(mean[1]) / static_cast<double>(n);
  sigma = c_plus >= c_minus ? 1 : -1;
  if (std::max(c_plus, c_minus) < kMinCoherence)
    return fmt::format(
        "the window's phase does not match the first window's (coherence {:.2f}, at least {:g}): "
        "the test surface moved, or the plate jumped",
        std::max(c_plus, c_minus), kMinCoherence);
  if (std::fabs(c_plus - c_minus) < kMinSignMargin)
    return fmt::format(
        "the phase and its mirror image match the reference alike (coherence {:.2f} and {:.2f}): "
        "a test surface this close to a plane cannot tell the direction of motion",
        c_plus, c_minus);
  // least squares plane through the residual, around its mean phase (small: no wraps)
  const double offset = std::arg(mean[sigma > 0 ? 0 : 1]);
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (std::size_t q = 0; q < ref_.pixels.size(); ++q) {
    const double phi = r.phase_rad.v[ref_.pixels[q]];
    if (!std::isfinite(phi))
      continue;
    const double known =
        w0.piston_rad + w0.tip_rad * ref_.y[q] + w0.tilt_rad * ref_.x[q] + ref_.phase_rad[q];
    const double res = offset + wrap(sigma * phi - known - offset);
    const Eigen::Vector3d row(1.0, ref_.y[q], ref_.x[q]);
    M += row * row.transpose();
    b += row * res;
  }
  const Eigen::Vector3d d = M.ldlt().solve(b);
  w0 = {w0.piston_rad + d(0), w0.tip_rad + d(1), w0.tilt_rad + d(2)};
  return {};
}

FringePose FringeTracker::pose_of(std::size_t frame, const Plane& d) const {
  const double nm_per_rad = p_.wavelength_nm / (4.0 * kPi);
  FringePose r;
  r.frame = frame;
  r.valid = true;
  r.piston_nm = nm_per_rad * d.piston_rad;
  // nm / m = 1e-9 rad = 1e-3 urad
  r.theta_x_urad = 1e-3 * nm_per_rad * d.tip_rad / pupil_radius_m_;
  r.theta_y_urad = -1e-3 * nm_per_rad * d.tilt_rad / pupil_radius_m_;
  r.points_um = tripod_.inverse({1e-3 * r.piston_nm, r.theta_x_urad, r.theta_y_urad});
  return r;
}

// Why the step from frame f - 1 (plane prev) to frame f (plane d) is not to be trusted, "" when
// it is: it reaches beyond max_step_rad somewhere in the pupil (the piston plus the plane's
// largest value at the unit disk's edge), or its centre step changes too much from the last.
std::string FringeTracker::step_problem(std::size_t f, const Plane& prev, const Plane& d) const {
  const double nm_per_rad = p_.wavelength_nm / (4.0 * kPi);
  const double step = d.piston_rad - prev.piston_rad;
  const double reach =
      std::fabs(step) + std::hypot(d.tip_rad - prev.tip_rad, d.tilt_rad - prev.tilt_rad);
  if (reach > p_.max_step_rad)
    return fmt::format(
        "step from frame {} to {} reaches {:.3f} rad ({:.1f} nm of mirror motion) in the pupil, "
        "at most {:.3f} rad ({:.1f} nm): too near a quarter wave ({:.1f} nm) to tell from its "
        "alias",
        f - 1, f, reach, reach * nm_per_rad, p_.max_step_rad, p_.max_step_rad * nm_per_rad,
        p_.wavelength_nm / 4.0);
  if (last_step_ && std::fabs(step - *last_step_) > p_.max_step_change_rad)
    return fmt::format(
        "step from frame {} to {} is {:.3f} rad after {:.3f} rad (a change of at most {:.3f} "
        "rad): a jump, or a step past a quarter wave read as its alias",
        f - 1, f, step, *last_step_, p_.max_step_change_rad);
  return {};
}

std::vector<FringePose> FringeTracker::process_window() {
  const std::vector<Map> frames(window_.begin(), window_.end());
  const std::size_t start = seen_ - frames.size();
  PhaseOptions o = p_.phase;
  o.algorithm = Algorithm::kTiltAia;
  o.step_tolerance_rad = std::numeric_limits<double>::infinity();  // the tracker checks steps
  const double guess = last_step_ ? std::fabs(*last_step_) : kPi / 2.0;
  o.steps_rad.clear();
  for (std::size_t k = 0; k < frames.size(); ++k)
    o.steps_rad.push_back(static_cast<double>(k) * guess);
  const PhaseResult r = wrapped_phase(frames, mask_, o);
  const std::string span = fmt::format("frames {}..{}", start, seen_ - 1);
  if (!(r.noise_rms <= p_.max_noise_to_modulation))
    return refuse_from(next_, fmt::format("{}: modulation too low, noise {:.3f} of it (at most "
                                          "{:g})",
                                          span, r.noise_rms, p_.max_noise_to_modulation));
  if (!r.converged)
    return refuse_from(next_, fmt::format("{}: {}", span, r.reason));
  int sigma = p_.first_direction;
  Plane w0;
  if (!have_phase_) {
    have_phase_ = true;
    for (std::size_t q = 0; q < ref_.pixels.size(); ++q)
      ref_.phase_rad[q] =
          sigma * r.phase_rad.v[ref_.pixels[q]];  // NaN where no modulation: skipped later
  } else {
    w0 = planes_[start];
    if (const std::string why = anchor(r, sigma, w0); !why.empty())
      return refuse_from(next_, fmt::format("{}: {}", span, why));
  }
  std::vector<FringePose> out;
  Plane prev = w0;  // the window's frame before the one at hand
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const std::size_t f = start + i;
    const FrameShift& s = r.shifts[i];
    Plane d{w0.piston_rad + sigma * s.piston_rad, w0.tip_rad + sigma * s.tip_rad,
            w0.tilt_rad + sigma * s.tilt_rad};
    if (f >= next_ && f > 0) {
      if (const std::string why = step_problem(f, prev, d); !why.empty()) {
        next_ = f;  // the frames before it stand
        std::vector<FringePose> refused = refuse_from(f, why);
        out.insert(out.end(), refused.begin(), refused.end());
        return out;
      }
      last_step_ = d.piston_rad - prev.piston_rad;
      // temporal unwrapping: the 2 pi multiple nearest the frame before
      d.piston_rad = planes_[f - 1].piston_rad + wrap(d.piston_rad - planes_[f - 1].piston_rad);
    }
    prev = d;
    if (f < next_)
      continue;
    planes_.push_back(d);
    FringePose pose = pose_of(f, d);
    pose.noise_to_modulation = r.noise_rms;
    out.push_back(std::move(pose));
  }
  next_ = seen_;
  return out;
}

// One frame against the reference phase: tilt-aware AIA's step (2) with the phase known,
//   I(x) = a + b cos(phi_ref(x) + piston + tip y + tilt x),
// piston (and a, b) solved linearly at the start's tip and tilt, so that it needs no start of
// its own, then Gauss-Newton on all five. Checked as tilt-aia checks its fits: the residual's
// white part (adjacent-pixel differences) over b is the noise, the rest a misfit.
FringeTracker::FrameFit FringeTracker::fit_frame(const Map& frame, const Plane& start) const {
  constexpr int kMaxIterations = 50;
  const PlaneFit f = fit_phase_plane(frame, ref_, start, kMaxIterations);
  FrameFit fit;
  fit.plane = f.plane;
  fit.noise = f.noise;
  if (!(f.contrast > 0.0))
    fit.reason = fmt::format(
        "the plane fit lost the fringes (modulation fitted at {:.3g}): the plate's tilt changed "
        "beyond the fit's reach since the frames before, or the fringes vanished",
        f.contrast);
  else if (!(fit.noise <= p_.max_noise_to_modulation))
    fit.reason = fmt::format("modulation too low, noise {:.3f} of it (at most {:g})", fit.noise,
                             p_.max_noise_to_modulation);
  else if (!f.settled)
    fit.reason = fmt::format("the plane fit did not settle in {} iterations", kMaxIterations);
  else if (!(f.misfit <= p_.phase.max_misfit))
    fit.reason = fmt::format(
        "the frame differs from the reference phase and its fitted plane by {:.4f} of the "
        "modulation beyond its noise (at most {:g}): the plate's tilt changed beyond the fit's "
        "reach since the frames before, or the test surface moved",
        f.misfit, p_.phase.max_misfit);
  return fit;
}

// The next frame after the reference window: fitted from the plane the frames before predict
// (constant velocity), its piston unwrapped against the frame before.
std::vector<FringePose> FringeTracker::track_frame(const Map& frame) {
  const std::size_t f = seen_ - 1;
  const Plane& last = planes_[f - 1];
  Plane predicted = last;
  if (f >= 2) {
    const Plane& before = planes_[f - 2];
    predicted = {2.0 * last.piston_rad - before.piston_rad, 2.0 * last.tip_rad - before.tip_rad,
                 2.0 * last.tilt_rad - before.tilt_rad};
  }
  const FrameFit fit = fit_frame(frame, predicted);
  if (!fit.reason.empty())
    return refuse_from(f, fmt::format("frame {}: {}", f, fit.reason));
  Plane d = fit.plane;
  d.piston_rad = last.piston_rad + wrap(d.piston_rad - last.piston_rad);
  if (const std::string why = step_problem(f, last, d); !why.empty())
    return refuse_from(f, why);
  last_step_ = d.piston_rad - last.piston_rad;
  planes_.push_back(d);
  next_ = seen_;
  FringePose pose = pose_of(f, d);
  pose.noise_to_modulation = fit.noise;
  return {pose};
}

}  // namespace piezoshift::psi
