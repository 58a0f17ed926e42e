#include "piezoshift/plant/geometry.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include <fmt/core.h>
#include <Eigen/LU>

namespace piezoshift::plant {

TwinGeometry make_twin_geometry(const GeometryParams& p) {
  if (!(p.actuator_radius_m > 0.0) || !std::isfinite(p.actuator_radius_m))
    throw std::invalid_argument("geometry: actuator_radius_m must be positive");
  Eigen::Matrix3d a;
  for (Eigen::Index r = 0; r < 3; ++r)
    for (Eigen::Index c = 0; c < 3; ++c)
      a(r, c) = p.transmission_matrix[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)];
  if (!a.allFinite())
    throw std::invalid_argument("geometry: the transmission matrix is not finite");
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(a);
  if (!lu.isInvertible())
    throw std::invalid_argument("geometry: the transmission matrix is singular");

  TwinGeometry g;
  const Eigen::Vector3d gain = a * Eigen::Vector3d::Ones();
  for (Eigen::Index i = 0; i < 3; ++i) {
    if (!(gain(i) > 0.0)) {
      throw std::invalid_argument(fmt::format(
          "geometry: row {} of the transmission matrix sums to {}, but a strain gauge gain "
          "g = A 1 must be positive",
          i + 1, gain(i)));
    }
    g.sgs_gain[static_cast<std::size_t>(i)] = gain(i);
  }
  const Eigen::Matrix3d w = lu.inverse() * gain.asDiagonal();

  const double phi0 = p.first_actuator_angle_deg * std::numbers::pi / 180.0;
  for (std::size_t i = 0; i < 3; ++i) {
    const double phi = phi0 + static_cast<double>(i) * 2.0 * std::numbers::pi / 3.0;
    g.actuators[i] = {p.actuator_radius_m * std::cos(phi), p.actuator_radius_m * std::sin(phi)};
  }
  for (std::size_t j = 0; j < 3; ++j) {
    double x = 0.0, y = 0.0;
    for (std::size_t i = 0; i < 3; ++i) {
      const double wji = w(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(i));
      g.barycentric[j][i] = wji;
      x += wji * g.actuators[i].x_m;
      y += wji * g.actuators[i].y_m;
    }
    g.points[j] = {x, y};
  }
  const kinematics::TripodGeometry legs(g.actuators);
  g.assembly_pose = legs.forward(p.height_errors_um);
  for (std::size_t j = 0; j < 3; ++j)
    g.assembly_points_um[j] = legs.displacement_at_um(g.assembly_pose, g.points[j]);
  return g;
}

}  // namespace piezoshift::plant
