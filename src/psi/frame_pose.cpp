#include "piezoshift/psi/frame_pose.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include <fmt/core.h>
#include <Eigen/Dense>

namespace piezoshift::psi {

namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

double median_of(std::vector<double> v) {
  if (v.empty())
    return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// The plate's motion at pupil point (x, y) [nm] for a pose: Z + theta_x y_m - theta_y x_m, with
// urad x m = 1e3 nm.
double motion_nm(const FramePose& p, double x, double y, double radius_m) {
  return p.piston_nm + 1e3 * radius_m * (p.theta_x_urad * y - p.theta_y_urad * x);
}

// The largest motion between two poses over the unit pupil [nm].
double edge_motion_nm(const FramePose& a, const FramePose& b, double radius_m) {
  const double tx = a.theta_x_urad - b.theta_x_urad, ty = a.theta_y_urad - b.theta_y_urad;
  return std::fabs(a.piston_nm - b.piston_nm) + 1e3 * radius_m * std::hypot(tx, ty);
}

}  // namespace

FramePoseReference frame_pose_reference(std::span<const Map> frames, const Mask& mask) {
  if (frames.size() < 4)
    throw std::invalid_argument("frame_pose_reference: at least four frames pi/2 apart");
  for (const Map& f : frames)
    if (f.width != mask.width || f.height != mask.height)
      throw std::invalid_argument("frame_pose_reference: a frame is not the mask's size");
  FramePoseReference r;
  r.mask = mask;
  r.pupil = pupil_of(mask);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  r.bias = Map(mask.width, mask.height, nan);
  r.modulation = Map(mask.width, mask.height, nan);
  r.phase_rad = Map(mask.width, mask.height, nan);
  const bool five = frames.size() >= 5;
  std::vector<double> b_all;
  for (std::size_t n = 0; n < mask.size(); ++n) {
    if (!mask.v[n])
      continue;
    const auto I = [&](std::size_t k) { return frames[k].v[n]; };
    // I_k = a + b cos(phi + k pi/2): four frames give b cos phi = (I0 - I2) / 2 and
    // b sin phi = (I3 - I1) / 2; five average the sets 0..3 and 1..4 (Hariharan's formula,
    // which cancels a step error to first order).
    const double c = five ? (I(0) - 2.0 * I(2) + I(4)) / 4.0 : (I(0) - I(2)) / 2.0;
    const double s = (I(3) - I(1)) / 2.0;
    const double a =
        five ? (I(0) + 2.0 * (I(1) + I(2) + I(3)) + I(4)) / 8.0 : (I(0) + I(1) + I(2) + I(3)) / 4.0;
    r.bias.v[n] = a;
    r.modulation.v[n] = std::hypot(c, s);
    r.phase_rad.v[n] = std::atan2(s, c);
    b_all.push_back(r.modulation.v[n]);
  }
  r.median_modulation = median_of(std::move(b_all));
  return r;
}

FramePose fit_frame_pose(const Map& frame, const FramePoseReference& ref, const FramePose& start,
                         const FramePoseOptions& o) {
  if (frame.width != ref.mask.width || frame.height != ref.mask.height)
    throw std::invalid_argument("fit_frame_pose: the frame is not the reference's size");
  const double w = kTwoPi * 2.0 / o.wavelength_nm;  // phase per nm of plate motion
  const double R = o.pupil_radius_m;
  FramePose p = start;
  p.valid = false;
  p.reason.clear();
  const auto fail = [&](std::string why) {
    p.valid = false;
    p.reason = std::move(why);
    return p;
  };
  // The piston and the contrast first, in closed form at the start's tilts: I - a =
  // (k cos e) b cos(alpha) - (k sin e) b sin(alpha), alpha = phi + w d(start), is linear in
  // (k cos e, k sin e), so e (the piston's change, within +-a quarter wave) and k > 0 need no
  // basin; the Gauss-Newton steps after it only refine.
  {
    Eigen::Matrix2d M = Eigen::Matrix2d::Zero();
    Eigen::Vector2d v = Eigen::Vector2d::Zero();
    for (int j = 0; j < frame.height; ++j)
      for (int i = 0; i < frame.width; ++i) {
        const std::size_t n = static_cast<std::size_t>(j) * frame.width + i;
        if (!ref.mask.v[n] || !std::isfinite(frame.v[n]))
          continue;
        const double b = ref.modulation.v[n];
        const double alpha =
            ref.phase_rad.v[n] + w * motion_nm(p, ref.pupil.x(i), ref.pupil.y(j), R);
        const Eigen::Vector2d u(b * std::cos(alpha), -b * std::sin(alpha));
        M.noalias() += u * u.transpose();
        v.noalias() += u * (frame.v[n] - ref.bias.v[n]);
      }
    const Eigen::Vector2d kc_ks = M.ldlt().solve(v);
    if (kc_ks.allFinite()) {
      p.contrast = kc_ks.norm();
      p.piston_nm += std::atan2(kc_ks[1], kc_ks[0]) / w;
    }
  }
  bool settled = false;
  double sum_r2 = 0.0;
  std::size_t count = 0;
  for (p.iterations = 0; p.iterations < o.max_iterations && !settled; ++p.iterations) {
    Eigen::Matrix4d JtJ = Eigen::Matrix4d::Zero();
    Eigen::Vector4d Jtr = Eigen::Vector4d::Zero();
    sum_r2 = 0.0;
    count = 0;
    for (int j = 0; j < frame.height; ++j)
      for (int i = 0; i < frame.width; ++i) {
        const std::size_t n = static_cast<std::size_t>(j) * frame.width + i;
        if (!ref.mask.v[n] || !std::isfinite(frame.v[n]))
          continue;
        const double x = ref.pupil.x(i), y = ref.pupil.y(j);
        const double b = ref.modulation.v[n];
        const double arg = ref.phase_rad.v[n] + w * motion_nm(p, x, y, R);
        const double cs = std::cos(arg), sn = std::sin(arg);
        const double r = frame.v[n] - ref.bias.v[n] - p.contrast * b * cs;
        // d model / d (k, Z, theta_x, theta_y)
        const double g = -p.contrast * b * sn * w;
        const Eigen::Vector4d J(b * cs, g, g * 1e3 * R * y, -g * 1e3 * R * x);
        JtJ.noalias() += J * J.transpose();
        Jtr.noalias() += J * r;
        sum_r2 += r * r;
        ++count;
      }
    if (count < 16)
      return fail("fewer than 16 pupil pixels with a finite value");
    const Eigen::Vector4d step = JtJ.ldlt().solve(Jtr);
    if (!step.allFinite())
      return fail("the fit's normal equations are singular (no fringes in the reference?)");
    p.contrast += step[0];
    p.piston_nm += step[1];
    p.theta_x_urad += step[2];
    p.theta_y_urad += step[3];
    const double moved = std::fabs(step[1]) + 1e3 * R * std::hypot(step[2], step[3]);
    settled = moved < o.tolerance_nm;
  }
  const double scale = std::fabs(p.contrast) * ref.median_modulation;
  p.misfit = scale > 0.0 ? std::sqrt(sum_r2 / static_cast<double>(count)) / scale : INFINITY;
  if (p.contrast < 0.0)
    return fail(
        fmt::format("the fringes fit inverted (contrast {:.3f}): the plate is about a "
                    "quarter wave from where the fit started, so its fringe order is not "
                    "certain",
                    p.contrast));
  if (!(p.contrast >= o.min_contrast))
    return fail(
        fmt::format("the fringes' contrast is {:.3f} of the reference's, below {} (fringes "
                    "lost: a blocked beam, a dark frame, a moved test piece)",
                    p.contrast, o.min_contrast));
  if (!settled)
    return fail(fmt::format("the fit did not settle to {} nm in {} iterations", o.tolerance_nm,
                            o.max_iterations));
  if (!(p.misfit <= o.max_misfit))
    return fail(
        fmt::format("the frame's residual from the fitted fringes is {:.3f} of their "
                    "modulation, above {} (not the reference's surface, or a pose beyond "
                    "a quarter wave of the start)",
                    p.misfit, o.max_misfit));
  if (const double moved = edge_motion_nm(p, start, R); moved > o.max_step_nm)
    return fail(
        fmt::format("the plate moved {:.1f} nm at the pupil's edge since the last frame, "
                    "above {} nm: its fringe order is not certain",
                    moved, o.max_step_nm));
  p.valid = true;
  return p;
}

}  // namespace piezoshift::psi
