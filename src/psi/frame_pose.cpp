#include "piezoshift/psi/frame_pose.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <fmt/core.h>
#include <Eigen/Dense>

#include "piezoshift/psi/median.hpp"

namespace piezoshift::psi {

namespace {

void require_size(const Map& frame, const PhaseReference& r, const char* who) {
  if (frame.width != r.width || frame.height != r.height || frame.size() != frame.v.size() ||
      frame.v.size() != static_cast<std::size_t>(r.width) * static_cast<std::size_t>(r.height))
    throw std::invalid_argument(fmt::format("{}: the frame is {} x {} px, the reference {} x {}",
                                            who, frame.width, frame.height, r.width, r.height));
}

// The model's two per-pixel factors: A_q, B_q (1 and 1 when the reference is uniform).
struct Factors {
  const PhaseReference& r;
  bool uniform() const { return r.bias.empty(); }
  double a(std::size_t q) const { return uniform() ? 1.0 : r.bias[q]; }
  double b(std::size_t q) const { return uniform() ? 1.0 : r.modulation[q]; }
};

// alpha, beta and the piston in closed form at the start's tip and tilt (the header).
void closed_form_start(const Map& frame, const PhaseReference& r, PlaneFit& fit) {
  const Factors f{r};
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  for (std::size_t q = 0; q < r.pixels.size(); ++q) {
    const double I = frame.v[r.pixels[q]];
    if (!std::isfinite(r.phase_rad[q]) || !std::isfinite(I))
      continue;
    const double th = r.phase_rad[q] + fit.plane.tip_rad * r.y[q] + fit.plane.tilt_rad * r.x[q];
    const Eigen::Vector3d row(f.a(q), f.b(q) * std::cos(th), -f.b(q) * std::sin(th));
    M.noalias() += row * row.transpose();
    v.noalias() += row * I;
  }
  const Eigen::Vector3d u = M.ldlt().solve(v);
  fit.bias = u(0);
  fit.contrast = std::hypot(u(1), u(2));
  fit.plane.piston_rad = std::atan2(u(2), u(1));
}

// The residual's RMS and its white part (adjacent pixels of a row), as tilt-aware AIA splits it.
void residual_split(const Map& frame, const PhaseReference& r, PlaneFit& fit) {
  const Factors f{r};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  double s2 = 0.0, d2 = 0.0, previous = nan;
  std::size_t n = 0, pairs = 0;
  const auto width = static_cast<std::size_t>(r.width);
  for (std::size_t q = 0; q < r.pixels.size(); ++q) {
    const std::size_t px = r.pixels[q];
    const double I = frame.v[px];
    double res = nan;
    if (std::isfinite(r.phase_rad[q]) && std::isfinite(I)) {
      const double th = r.phase_rad[q] + fit.plane.piston_rad + fit.plane.tip_rad * r.y[q] +
                        fit.plane.tilt_rad * r.x[q];
      res = I - fit.bias * f.a(q) - fit.contrast * f.b(q) * std::cos(th);
      s2 += res * res;
      ++n;
      if (q > 0 && px == r.pixels[q - 1] + 1 && px % width != 0 && std::isfinite(previous)) {
        d2 += (res - previous) * (res - previous);
        ++pairs;
      }
    }
    previous = res;
  }
  fit.pixels = n;
  const double rms = n ? std::sqrt(s2 / static_cast<double>(n)) : nan;
  const double white = pairs ? std::sqrt(d2 / (2.0 * static_cast<double>(pairs))) : rms;
  const double unit = fit.contrast * r.modulation_scale;
  fit.noise = unit > 0.0 ? white / unit : std::numeric_limits<double>::infinity();
  fit.misfit = unit > 0.0 ? std::sqrt(std::max(0.0, rms * rms - white * white)) / unit
                          : std::numeric_limits<double>::infinity();
}

}  // namespace

PhaseReference phase_reference(const Mask& mask) {
  const Pupil pupil = pupil_of(mask);  // throws for an empty mask
  PhaseReference r;
  r.width = mask.width;
  r.height = mask.height;
  const auto w = static_cast<std::size_t>(mask.width);
  for (std::size_t q = 0; q < mask.size(); ++q)
    if (mask.v[q]) {
      r.pixels.push_back(q);
      r.x.push_back(pupil.x(static_cast<int>(q % w)));
      r.y.push_back(pupil.y(static_cast<int>(q / w)));
    }
  r.phase_rad.assign(r.pixels.size(), std::numeric_limits<double>::quiet_NaN());
  return r;
}

PlaneFit fit_phase_plane(const Map& frame, const PhaseReference& r, const PhasePlane& start,
                         int max_iterations, double tolerance_rad) {
  using Vec5 = Eigen::Matrix<double, 5, 1>;
  using Mat5 = Eigen::Matrix<double, 5, 5>;
  require_size(frame, r, "fit_phase_plane");
  const Factors f{r};
  PlaneFit fit;
  fit.plane = start;
  closed_form_start(frame, r, fit);
  for (; fit.iterations < max_iterations && fit.contrast > 0.0 && !fit.settled; ++fit.iterations) {
    Mat5 JtJ = Mat5::Zero();
    Vec5 Jtr = Vec5::Zero();
    for (std::size_t q = 0; q < r.pixels.size(); ++q) {
      const double I = frame.v[r.pixels[q]];
      if (!std::isfinite(r.phase_rad[q]) || !std::isfinite(I))
        continue;
      const double th = r.phase_rad[q] + fit.plane.piston_rad + fit.plane.tip_rad * r.y[q] +
                        fit.plane.tilt_rad * r.x[q];
      const double c = std::cos(th), g = -fit.contrast * f.b(q) * std::sin(th);
      Vec5 J;
      J << f.a(q), f.b(q) * c, g, g * r.y[q], g * r.x[q];
      JtJ.selfadjointView<Eigen::Lower>().rankUpdate(J);
      Jtr.noalias() += J * (I - fit.bias * f.a(q) - fit.contrast * f.b(q) * c);
    }
    JtJ.triangularView<Eigen::Upper>() = JtJ.transpose();
    const Vec5 dx = JtJ.ldlt().solve(Jtr);
    if (!dx.allFinite())
      break;
    fit.bias += dx(0);
    fit.contrast += dx(1);
    fit.plane = {fit.plane.piston_rad + dx(2), fit.plane.tip_rad + dx(3),
                 fit.plane.tilt_rad + dx(4)};
    fit.settled = std::max({std::fabs(dx(2)), std::fabs(dx(3)), std::fabs(dx(4))}) < tolerance_rad;
  }
  residual_split(frame, r, fit);
  return fit;
}

FramePoseReference frame_pose_reference(std::span<const Map> frames, const Mask& mask,
                                        double pupil_radius_m) {
  if (frames.size() < 4)
    throw std::invalid_argument("frame_pose_reference: at least four frames pi/2 apart");
  for (const Map& f : frames)
    if (f.width != mask.width || f.height != mask.height || f.v.size() != mask.size())
      throw std::invalid_argument("frame_pose_reference: a frame is not the mask's size");
  FramePoseReference ref;
  ref.pupil_radius_m = pupil_radius_m;
  PhaseReference& r = ref.fringes;
  r = phase_reference(mask);
  r.bias.resize(r.pixels.size());
  r.modulation.resize(r.pixels.size());
  const bool five = frames.size() >= 5;
  for (std::size_t q = 0; q < r.pixels.size(); ++q) {
    const auto I = [&](std::size_t k) { return frames[k].v[r.pixels[q]]; };
    // I_k = a + b cos(phi + k pi/2): four frames give b cos phi = (I0 - I2) / 2 and
    // b sin phi = (I3 - I1) / 2; five average the sets 0..3 and 1..4.
    const double c = five ? (I(0) - 2.0 * I(2) + I(4)) / 4.0 : (I(0) - I(2)) / 2.0;
    const double s = (I(3) - I(1)) / 2.0;
    r.bias[q] =
        five ? (I(0) + 2.0 * (I(1) + I(2) + I(3)) + I(4)) / 8.0 : (I(0) + I(1) + I(2) + I(3)) / 4.0;
    r.modulation[q] = std::hypot(c, s);
    r.phase_rad[q] = std::atan2(s, c);
  }
  r.modulation_scale = median_of(r.modulation);
  return ref;
}

FramePose fit_frame_pose(const Map& frame, const FramePoseReference& ref, const FramePose& start,
                         const FramePoseOptions& o) {
  const double w = 4.0 * std::numbers::pi / o.wavelength_nm;  // phase per nm of plate motion
  const double edge_nm = 1e3 * ref.pupil_radius_m;            // nm at the edge per urad
  const PhasePlane from{w * start.piston_nm, w * edge_nm * start.theta_x_urad,
                        -w * edge_nm * start.theta_y_urad};
  const PlaneFit fit =
      fit_phase_plane(frame, ref.fringes, from, o.max_iterations, w * o.tolerance_nm);
  FramePose p;
  // The closed form's piston is wrapped: the fringe order is the start's.
  p.piston_nm = start.piston_nm +
                std::remainder(fit.plane.piston_rad - from.piston_rad, 2.0 * std::numbers::pi) / w;
  p.theta_x_urad = fit.plane.tip_rad / (w * edge_nm);
  p.theta_y_urad = -fit.plane.tilt_rad / (w * edge_nm);
  p.contrast = fit.contrast;
  p.noise = fit.noise;
  p.misfit = fit.misfit;
  p.iterations = fit.iterations;
  const auto fail = [&](std::string why) {
    p.reason = std::move(why);
    return p;
  };
  if (fit.pixels < 16)
    return fail("fewer than 16 pupil pixels with a finite value");
  if (p.contrast < 0.0)
    return fail(
        fmt::format("the fringes fit inverted (contrast {:.3f}): the plate is about a "
                    "quarter wave from where the fit started, so its fringe order is not "
                    "certain",
                    p.contrast));
  p.fringes_lost = !(p.contrast >= o.min_contrast);
  if (p.fringes_lost)
    return fail(
        fmt::format("the fringes' contrast is {:.3f} of the reference's, below {} (fringes "
                    "lost: a blocked beam, a dark frame, a moved test piece)",
                    p.contrast, o.min_contrast));
  if (!fit.settled)
    return fail(fmt::format("the fit did not settle to {} nm in {} iterations", o.tolerance_nm,
                            o.max_iterations));
  if (!(p.misfit <= o.max_misfit))
    return fail(
        fmt::format("the frame differs from the fitted fringes by {:.3f} of their "
                    "modulation beyond its noise, above {} (not the reference's surface, "
                    "or a tilt beyond the fit's reach from the start)",
                    p.misfit, o.max_misfit));
  const double moved = std::fabs(p.piston_nm - start.piston_nm) +
                       edge_nm * std::hypot(p.theta_x_urad - start.theta_x_urad,
                                            p.theta_y_urad - start.theta_y_urad);
  if (moved > o.max_step_nm)
    return fail(
        fmt::format("the plate moved {:.1f} nm at the pupil's edge since the start, above "
                    "{} nm: its fringe order is not certain",
                    moved, o.max_step_nm));
  p.valid = true;
  return p;
}

}  // namespace piezoshift::psi
