#pragma once
// Where the actuators and the measurement points are, derived from the paper's identified motion
// transmission matrix A (Section 4; S = A Z_S, second Eq. 8).
//
// Model: the plate is rigid, so the displacement at any plate point is affine in position, and a
// point P_j with barycentric coordinates W_j on the actuator triangle moves
//   z_Pj = sum_i W_ji x_i,   sum_i W_ji = 1               (x_i: leg displacements at the plate)
// The strain gauge of actuator i reads, in the controller's nominal micrometres (1.6 um/V),
//   S_i = g_i x_i                                         (g: SGS reading per um of leg motion)
// so S = G W^-1 Z: the paper's A factors as A = G W^-1, and since W 1 = 1,
//   g = A 1,   W = A^-1 G,   G = diag(g).
// This factorization is unique. With the paper's A: g = (0.8359, 0.8953, 0.7738) and W =
//   [[-0.3644, 0.6974, 0.6670], [0.7573, -0.4298, 0.6724], [0.3445, 0.8451, -0.1896]]:
// each P_j lies outside the actuator triangle, opposite actuator j, 0.9 to 1.15 radii from the
// centre. No rigid geometry can make g differ from 1 (W 1 = 1 for any points), so g belongs to the
// sensor chain: it is the gauge reading per um of leg motion, set by the conditioner's
// calibration and by how much the stack elongates per um of leg motion (contact.hpp).
//
// Actuators: at 120 deg on a circle of radius R (not in the paper: assumed), actuator i (0-based)
// at angle phi_0 + i 120 deg, counterclockwise seen from above; the centre O is the plate's centre
// of mass and the origin of Eq. 5's Z. Measurement points: P_j = sum_i W_ji a_i.
// Leg height errors h_i (the parallelism the paper corrects with ground washers) tilt the plate
// as assembled; with small angles they add a constant pose and change no displacement.
#include <array>

#include "piezoshift/control/transmission_matrix.hpp"
#include "piezoshift/control/vec3.hpp"
#include "piezoshift/kinematics/tripod.hpp"

namespace piezoshift::plant {

struct GeometryParams {
  double actuator_radius_m = 0.05;         //!< R, assumed (the paper gives no dimension)
  double first_actuator_angle_deg = 90.0;  //!< phi_0: actuator 1 on +y
  //! The paper's identified A (Section 4), the source of g and W; default from the controller.
  control::Mat3 transmission_matrix = control::TransmissionMatrix{}.a;
  //! h_i: leg heights after the washer correction [um]. Assumed residual of a CMM-measured,
  //! ground-washer correction (a few um); the paper gives no figure.
  std::array<double, 3> height_errors_um{0.0, 1.5, -1.0};

  bool operator==(const GeometryParams&) const = default;
};

struct TwinGeometry {
  std::array<kinematics::PlatePoint, 3> actuators{};  //!< a_i [m]
  std::array<kinematics::PlatePoint, 3> points{};     //!< P_j [m]
  control::Vec3 sgs_gain{};                           //!< g = A 1
  control::Mat3 barycentric{};                        //!< W: rows j (points), columns i (legs)
  kinematics::PlatePose assembly_pose{};              //!< the plate's pose from h alone
  control::Vec3 assembly_points_um{};                 //!< heights of P_j from h alone
};

//! Builds the geometry. Throws std::invalid_argument when A is singular, a g_i is not positive
//! (a gauge must read motion with the sign it has), or R is not positive.
TwinGeometry make_twin_geometry(const GeometryParams& params);

}  // namespace piezoshift::plant
