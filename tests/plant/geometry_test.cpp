// The geometry derived from the paper's A, and the contact identification.
#include <cmath>

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "piezoshift/plant/contact.hpp"
#include "piezoshift/plant/geometry.hpp"

namespace piezoshift::plant {
namespace {

TEST(Geometry, GainsAreTheRowSumsOfThePapersA) {
  const TwinGeometry g = make_twin_geometry({});
  EXPECT_NEAR(g.sgs_gain[0], -0.4218 + 0.6030 + 0.6547, 1e-12);  // 0.8359
  EXPECT_NEAR(g.sgs_gain[1], 0.3482 - 0.1491 + 0.6962, 1e-12);   // 0.8953
  EXPECT_NEAR(g.sgs_gain[2], 0.6321 + 0.4397 - 0.2980, 1e-12);   // 0.7738
}

TEST(Geometry, BarycentricWeightsReproduceAAndPutEachPointOppositeItsActuator) {
  const GeometryParams p;
  const TwinGeometry g = make_twin_geometry(p);
  const double expected[3][3] = {
      {-0.3644, 0.6974, 0.6670}, {0.7573, -0.4298, 0.6724}, {0.3445, 0.8451, -0.1896}};
  Eigen::Matrix3d w, a;
  for (int j = 0; j < 3; ++j) {
    double row = 0.0;
    for (int i = 0; i < 3; ++i) {
      const auto ju = static_cast<std::size_t>(j), iu = static_cast<std::size_t>(i);
      EXPECT_NEAR(g.barycentric[ju][iu], expected[j][i], 1e-4);
      w(j, i) = g.barycentric[ju][iu];
      a(j, i) = p.transmission_matrix[ju][iu];
      row += g.barycentric[ju][iu];
    }
    EXPECT_NEAR(row, 1.0, 1e-12);
    // negative weight on its own actuator: outside the triangle, across from actuator j
    EXPECT_LT(g.barycentric[static_cast<std::size_t>(j)][static_cast<std::size_t>(j)], 0.0);
  }
  const Eigen::Vector3d gain(g.sgs_gain[0], g.sgs_gain[1], g.sgs_gain[2]);
  const Eigen::Matrix3d a_back = gain.asDiagonal() * w.inverse();  // A = G W^-1
  EXPECT_LT((a_back - a).cwiseAbs().maxCoeff(), 1e-12);
  // P1 lies across the centre from actuator 1 (at +y): below the x axis
  EXPECT_LT(g.points[0].y_m, -0.04);
  EXPECT_NEAR(std::hypot(g.points[0].x_m, g.points[0].y_m), 0.05235, 1e-4);
}

TEST(Geometry, HeightErrorsTiltTheAssembledPlateOnly) {
  GeometryParams p;
  p.height_errors_um = {0.0, 1.5, -1.0};
  const TwinGeometry g = make_twin_geometry(p);
  EXPECT_NEAR(g.assembly_pose.z_um, 0.5 / 3.0, 1e-12);  // mean of the leg heights at O
  // each point's height is its barycentric mix of the leg heights
  for (std::size_t j = 0; j < 3; ++j) {
    const double z = g.barycentric[j][1] * 1.5 - g.barycentric[j][2] * 1.0;
    EXPECT_NEAR(g.assembly_points_um[j], z, 1e-9);
  }
}

TEST(Geometry, RejectsASingularMatrixOrANegativeGain) {
  GeometryParams p;
  p.transmission_matrix = {{{1, 2, 3}, {2, 4, 6}, {0, 1, 1}}};
  EXPECT_THROW(make_twin_geometry(p), std::invalid_argument);
  p.transmission_matrix = {{{-1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  EXPECT_THROW(make_twin_geometry(p), std::invalid_argument);
}

TEST(Contact, RigidContactIsEquation1AndTheIdentificationInvertsIt) {
  const double ka = 70.0, km = 6.7763;
  const double ks = series_stiffness_N_per_um(ka, INFINITY);
  EXPECT_EQ(ks, ka);
  EXPECT_NEAR(16.0 * ks / (ks + km), 14.588, 1e-3);  // the paper's 14.6 um
  const double kc = identify_contact_stiffness_N_per_um(12.9, 16.0, ka, km);
  const double ks2 = series_stiffness_N_per_um(ka, kc);
  EXPECT_NEAR(16.0 * ks2 / (ks2 + km), 12.9, 1e-12);
  EXPECT_THROW(identify_contact_stiffness_N_per_um(14.7, 16.0, ka, km), std::invalid_argument);
}

}  // namespace
}  // namespace piezoshift::plant
