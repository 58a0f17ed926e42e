#pragma once
// The top plate (paper, Section 2.3, Figures 3 and 4), a rigid body moving in Z, theta_x and
// theta_y on the three legs. The paper gives no dimensions or mass; the twin assumes a solid disc
// of the mechanisms' 45 steel (density from Table 2, taken from the design's MaterialParams) large
// enough to carry the three measurement points, which lie up to 1.15 actuator radii from the
// centre (geometry.hpp), plus an optional payload at its centre (the reference mirror, the
// interferometer's retroreflector):
//   m_p = rho pi r^2 t + m_payload
//   I_x = I_y = rho pi r^2 t (3 r^2 + t^2) / 12          disc about a diameter through O
// Only the dynamics (the loaded modes) depend on these; every static result is independent of
// them.

namespace piezoshift::plant {

struct PlateParams {
  double radius_m = 0.065;       //!< assumed: clears the measurement points (up to 0.057 m out)
  double thickness_m = 0.010;    //!< assumed
  double payload_mass_kg = 0.0;  //!< mirror or optics at the centre; none in the paper's tests

  bool operator==(const PlateParams&) const = default;
};

struct PlateInertia {
  double mass_kg = 0.0;
  double inertia_x_kg_m2 = 0.0;  //!< about the x axis through O
  double inertia_y_kg_m2 = 0.0;  //!< about the y axis through O
};

inline PlateInertia plate_inertia(const PlateParams& p, double density_kg_per_m3) {
  constexpr double kPi = 3.14159265358979323846;
  const double disc = density_kg_per_m3 * kPi * p.radius_m * p.radius_m * p.thickness_m;
  const double i = disc * (3.0 * p.radius_m * p.radius_m + p.thickness_m * p.thickness_m) / 12.0;
  return PlateInertia{disc + p.payload_mass_kg, i, i};
}

}  // namespace piezoshift::plant
