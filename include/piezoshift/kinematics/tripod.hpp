#pragma once
// Rigid-plate kinematics of the tripod (paper, Section 2.3, Figure 4, Eq. 5).
//
// Plate frame: origin O at the plate's centroid, z up. For small angles the displacement at a
// plate point (x, y) is
//   z(x, y) = Z + theta_x * y - theta_y * x
// (theta_x about +x, theta_y about +y, right-handed). Three non-collinear points P1..P3 fix the
// pose; forward() solves the 3x3 system, inverse() evaluates it.
//
// The paper's layout: P1 = (0, 2/3 L12), P2 = (-L23/2, -L12/3), P3 = (L23/2, -L12/3), where L12 is
// the distance from P1 to the line P2P3 and L23 the distance P2P3. Then forward() is exactly
//   Z = (Z1 + Z2 + Z3) / 3,  theta_x = (2 Z1 - Z2 - Z3) / (2 L12),  theta_y = (Z2 - Z3) / L23.
#include <array>

#include <Eigen/Core>

namespace piezoshift::kinematics {

struct PlatePoint {
  double x_m = 0.0;
  double y_m = 0.0;
};

struct PlatePose {
  double z_um = 0.0;          //!< Z, piston at the origin O
  double theta_x_urad = 0.0;  //!< tip about x
  double theta_y_urad = 0.0;  //!< tilt about y
};

using PointDisplacements = std::array<double, 3>;  //!< Z1, Z2, Z3 in um

class TripodGeometry {
 public:
  //! Throws std::invalid_argument when the points are (nearly) collinear or not finite.
  explicit TripodGeometry(const std::array<PlatePoint, 3>& points);

  //! The paper's layout (see above) from L12 and L23 in metres.
  static TripodGeometry paper_layout(double l12_m, double l23_m);
  //! Three points at 120 deg on a circle of radius_m, the first at angle first_angle_rad from +x.
  static TripodGeometry on_circle(double radius_m, double first_angle_rad);

  //! (Z1, Z2, Z3) -> (Z, theta_x, theta_y)
  PlatePose forward(const PointDisplacements& z_um) const;
  //! (Z, theta_x, theta_y) -> (Z1, Z2, Z3)
  PointDisplacements inverse(const PlatePose& pose) const;
  //! Displacement at any plate point for a pose.
  double displacement_at_um(const PlatePose& pose, const PlatePoint& p) const;

  const std::array<PlatePoint, 3>& points() const { return points_; }

 private:
  std::array<PlatePoint, 3> points_;
  Eigen::Matrix3d to_points_;    // rows [1, y_i, -x_i], with angles in rad and lengths in m
  Eigen::Matrix3d from_points_;  // its inverse
};

}  // namespace piezoshift::kinematics
