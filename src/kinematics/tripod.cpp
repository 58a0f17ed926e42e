#include "piezoshift/kinematics/tripod.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include <Eigen/LU>

namespace piezoshift::kinematics {
namespace {

// um and urad are carried as such: z_um = Z_um + theta_urad * 1e-6 * y_m * 1e6 = Z + theta * y_m.
constexpr double kUradToUmPerMetre = 1.0;  // 1 urad over 1 m of lever is 1 um

}  // namespace

TripodGeometry::TripodGeometry(const std::array<PlatePoint, 3>& points) : points_(points) {
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& p = points_[i];
    if (!std::isfinite(p.x_m) || !std::isfinite(p.y_m)) {
      throw std::invalid_argument("tripod geometry: point P" + std::to_string(i + 1) +
                                  " is not finite");
    }
    to_points_.row(static_cast<Eigen::Index>(i)) << 1.0, p.y_m * kUradToUmPerMetre,
        -p.x_m * kUradToUmPerMetre;
  }
  // Twice the triangle's area over the square of its longest side: 0 for collinear points.
  const double ax = points_[1].x_m - points_[0].x_m, ay = points_[1].y_m - points_[0].y_m;
  const double bx = points_[2].x_m - points_[0].x_m, by = points_[2].y_m - points_[0].y_m;
  const double cx = points_[2].x_m - points_[1].x_m, cy = points_[2].y_m - points_[1].y_m;
  const double longest2 = std::max({ax * ax + ay * ay, bx * bx + by * by, cx * cx + cy * cy});
  const double area2 = std::fabs(ax * by - ay * bx);
  if (!(longest2 > 0.0) || area2 / longest2 < 1e-9) {
    throw std::invalid_argument("tripod geometry: the three points are collinear or coincide");
  }
  from_points_ = to_points_.inverse();
}

TripodGeometry TripodGeometry::paper_layout(double l12_m, double l23_m) {
  if (!(l12_m > 0.0) || !(l23_m > 0.0)) {
    throw std::invalid_argument("tripod geometry: L12 and L23 must be positive");
  }
  return TripodGeometry({PlatePoint{0.0, 2.0 / 3.0 * l12_m}, PlatePoint{-l23_m / 2, -l12_m / 3},
                         PlatePoint{l23_m / 2, -l12_m / 3}});
}

TripodGeometry TripodGeometry::on_circle(double radius_m, double first_angle_rad) {
  if (!(radius_m > 0.0))
    throw std::invalid_argument("tripod geometry: radius must be positive");
  std::array<PlatePoint, 3> pts{};
  for (std::size_t i = 0; i < 3; ++i) {
    const double a = first_angle_rad + static_cast<double>(i) * 2.0 * std::numbers::pi / 3.0;
    pts[i] = PlatePoint{radius_m * std::cos(a), radius_m * std::sin(a)};
  }
  return TripodGeometry(pts);
}

PlatePose TripodGeometry::forward(const PointDisplacements& z_um) const {
  const Eigen::Vector3d pose = from_points_ * Eigen::Vector3d(z_um[0], z_um[1], z_um[2]);
  return PlatePose{pose[0], pose[1], pose[2]};
}

PointDisplacements TripodGeometry::inverse(const PlatePose& pose) const {
  const Eigen::Vector3d z =
      to_points_ * Eigen::Vector3d(pose.z_um, pose.theta_x_urad, pose.theta_y_urad);
  return {z[0], z[1], z[2]};
}

double TripodGeometry::displacement_at_um(const PlatePose& pose, const PlatePoint& p) const {
  return pose.z_um + (pose.theta_x_urad * p.y_m - pose.theta_y_urad * p.x_m) * kUradToUmPerMetre;
}

}  // namespace piezoshift::kinematics
