#include "piezoshift/host/stage_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/core.h>
#include <Eigen/LU>

namespace piezoshift::host {

namespace {

constexpr double kSlack = 1e-9;  // um: round-off allowance at the range ends

kinematics::PlatePose to_pose(const AxisValues& v) {
  return kinematics::PlatePose{v[0], v[1], v[2]};
}

// The cubic's inversion interval: wide enough for any gauge reading of a working stage.
double inverse_lo(double z_max_um) {
  return -z_max_um;
}
double inverse_hi(double z_max_um) {
  return 2.0 * z_max_um;
}

}  // namespace

const char* axis_name(Axis axis) noexcept {
  switch (axis) {
    case Axis::kZ:
      return "Z";
    case Axis::kU:
      return "U";
    case Axis::kV:
      return "V";
  }
  return "?";
}

const char* axis_unit(Axis axis) noexcept {
  return axis == Axis::kZ ? "um" : "urad";
}

StageModelParams stage_model_params(const plant::GeometryParams& geometry,
                                    const control::SemiClosedLoopParams& controller) {
  const plant::TwinGeometry g = plant::make_twin_geometry(geometry);
  StageModelParams p;
  p.controller = controller;
  p.measurement_points = g.points;
  p.actuators = g.actuators;
  return p;
}

StageModel::StageModel(const StageModelParams& params)
    : params_(params), points_(params.measurement_points), feedforward_(params.controller) {
  if (!(params.z_max_um > 0.0) || !std::isfinite(params.z_max_um))
    throw std::invalid_argument("stage model: the travel z_max_um must be > 0");
  if (!(params.z_min_um >= 0.0 && params.z_min_um < params.z_max_um))
    throw std::invalid_argument("stage model: the travel z_min_um must be in [0, z_max_um)");
  if (!(params.amplifier_gain > 0.0) || !(params.channel_max_V > 0.0))
    throw std::invalid_argument("stage model: amplifier gain and channel range must be > 0");
  Eigen::Matrix3d a;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      a(r, c) = params.controller.matrix.a[r][c];
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(a);
  if (!lu.isInvertible())
    throw std::invalid_argument("stage model: the transmission matrix A is singular");
  a_inverse_ = lu.inverse();

  // p must be increasing where positions are estimated: p' is a quadratic, so its minimum on the
  // interval is at an end or at the vertex.
  const control::CubicPolynomial& p = params.controller.polynomial;
  const double lo = inverse_lo(params.z_max_um);
  const double hi = inverse_hi(params.z_max_um);
  double slope_min = std::min(p.derivative(lo), p.derivative(hi));
  if (p.p3 != 0.0) {
    const double vertex = -p.p2 / (3.0 * p.p3);
    if (vertex > lo && vertex < hi)
      slope_min = std::min(slope_min, p.derivative(vertex));
  }
  if (!(slope_min > 0.0)) {
    throw std::invalid_argument(
        fmt::format("stage model: the cubic p is not increasing on [{:g}, {:g}] um", lo, hi));
  }

  const Vec3 s_max = feedforward_.actuator_targets(control::filled(params.z_max_um));
  actuator_max_um_ = s_max;

  Eigen::Matrix3d mix;
  double y_max = 0.0;
  double x_max = 0.0;
  for (const auto& a_i : params.actuators) {
    y_max = std::max(y_max, std::fabs(a_i.y_m));
    x_max = std::max(x_max, std::fabs(a_i.x_m));
  }
  if (!(y_max > 0.0) || !(x_max > 0.0))
    throw std::invalid_argument("stage model: the actuators must span the plate in x and y");
  for (int i = 0; i < 3; ++i) {
    mix(i, 0) = 1.0;
    mix(i, 1) = params.actuators[static_cast<std::size_t>(i)].y_m / y_max;
    mix(i, 2) = -params.actuators[static_cast<std::size_t>(i)].x_m / x_max;
  }
  const Eigen::FullPivLU<Eigen::Matrix3d> mix_lu(mix);
  if (!mix_lu.isInvertible())
    throw std::invalid_argument("stage model: the actuators are collinear");
  mix_ = mix;
  unmix_ = mix_lu.inverse();

  // Travel limits (header comment): Z over the calibrated travel, U and V by bisection from the
  // mid-travel pose, where every actuator has room both ways.
  min_ = {params.z_min_um, 0.0, 0.0};
  max_ = {params.z_max_um, 0.0, 0.0};
  const double z_mid = 0.5 * params.z_max_um;
  if (reachable({z_mid, 0.0, 0.0})) {
    for (std::size_t axis = 1; axis < 3; ++axis) {
      for (double sign : {-1.0, 1.0}) {
        double ok = 0.0;
        double bad = 1e7;  // urad: far beyond any plate of this size
        for (int it = 0; it < 80; ++it) {
          const double mid = 0.5 * (ok + bad);
          AxisValues pose{z_mid, 0.0, 0.0};
          pose[axis] = sign * mid;
          (reachable(pose) ? ok : bad) = mid;
        }
        (sign < 0 ? min_ : max_)[axis] = sign * ok;
      }
    }
  }
}

Vec3 StageModel::points_for(const AxisValues& pose) const {
  const auto z = points_.inverse(to_pose(pose));
  return Vec3{z[0], z[1], z[2]};
}

AxisValues StageModel::pose_from_points(const Vec3& z_um) const {
  const kinematics::PlatePose p = points_.forward({z_um[0], z_um[1], z_um[2]});
  return {p.z_um, p.theta_x_urad, p.theta_y_urad};
}

AxisValues StageModel::pose_from_sgs(const Vec3& sgs_V) const {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Eigen::Vector3d y;
  for (int i = 0; i < 3; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    if (!std::isfinite(sgs_V[ui]))
      return {nan, nan, nan};
    y[i] = params_.controller.scaling[ui].sgs_to_um(sgs_V[ui]);
  }
  const Eigen::Vector3d zs = a_inverse_ * y;
  const control::CubicPolynomial& p = params_.controller.polynomial;
  const double lo = inverse_lo(params_.z_max_um);
  const double hi = inverse_hi(params_.z_max_um);
  Vec3 z{};
  for (int i = 0; i < 3; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    const control::InverseResult r = control::inverse(p, zs[i], lo, hi);
    if (r.status == control::InverseStatus::kOk) {
      z[ui] = r.x;
    } else {  // beyond the interval (a broken gauge): extend linearly from the nearer end
      const double end = zs[i] < p(lo) ? lo : hi;
      z[ui] = end + (zs[i] - p(end)) / p.derivative(end);
    }
  }
  return pose_from_points(z);
}

std::string StageModel::unreachable_reason(const AxisValues& pose) const {
  for (double v : pose)
    if (!std::isfinite(v))
      return "the pose is not finite";
  const Vec3 z = points_for(pose);
  for (std::size_t i = 0; i < 3; ++i) {
    if (z[i] < params_.z_min_um - kSlack || z[i] > params_.z_max_um + kSlack) {
      return fmt::format("point P{} would be at {:.4f} um, outside [{:.4f}, {:.4f}] um", i + 1,
                         z[i], params_.z_min_um, params_.z_max_um);
    }
  }
  const Vec3 s = feedforward_.actuator_targets(z);
  for (std::size_t i = 0; i < 3; ++i) {
    if (s[i] < -kSlack || s[i] > actuator_max_um_[i] + kSlack) {
      return fmt::format("actuator {} would be asked for {:.4f} um, outside [0, {:.4f}] um", i + 1,
                         s[i], actuator_max_um_[i]);
    }
  }
  return {};
}

Vec3 StageModel::channel_V_for(const AxisValues& open_loop_V) const {
  const Eigen::Vector3d v = mix_ * Eigen::Vector3d(open_loop_V[0], open_loop_V[1], open_loop_V[2]);
  return Vec3{v[0], v[1], v[2]};
}

Vec3 StageModel::channel_V_from_daq(const Vec3& daq_V) const {
  Vec3 v{};
  for (std::size_t i = 0; i < v.size(); ++i)
    v[i] = daq_V[i] * params_.amplifier_gain;
  return v;
}

AxisValues StageModel::open_loop_for(const Vec3& channel_V) const {
  const Eigen::Vector3d v = unmix_ * Eigen::Vector3d(channel_V[0], channel_V[1], channel_V[2]);
  return {v[0], v[1], v[2]};
}

}  // namespace piezoshift::host
