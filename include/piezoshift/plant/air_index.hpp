#pragma once
// The phase refractive index of air: Edlen's equation (Metrologia 2, 71, 1966) as updated by
// K. P. Birch and M. J. Downs, "An updated Edlen equation for the refractive index of air",
// Metrologia 30, 155 (1993), with their "Correction to the updated Edlen equation for the
// refractive index of air", Metrologia 31, 315 (1994):
//   sigma = 1 / lambda_vac                                                       [um^-1]
//   (n - 1)_s 1e8  = 8342.54 + 2406147 / (130 - sigma^2) + 15998 / (38.9 - sigma^2)
//                    (standard air: dry, 15 degC, 101 325 Pa, 450 ppm CO2)
//   (n - 1)_tp     = p (n - 1)_s [1 + 1e-8 (0.601 - 0.00972 t) p] / [96095.43 (1 + 0.003661 t)]
//                    (p [Pa], t [degC])
//   n_tpf - n_tp   = -f (3.7345 - 0.0401 sigma^2) 1e-10          (f: water vapour pressure [Pa])
// The constants as NIST's Engineering Metrology Toolbox lists them (J. A. Stone and J. H.
// Zimmerman, "Index of refraction of air", Appendix A-IV, emtoolbox.nist.gov/Wavelength); NIST's
// "modified Edlen" multiplies the water term by 292.75 / T [K], which we leave out: this is
// Birch and Downs' own equation. Stated uncertainty about 1e-8 (3 sigma) for 350-650 nm near
// laboratory conditions; the twin uses only its changes, which are better known than that.
//
// Near 20 degC, 101 325 Pa and 633 nm: n - 1 = 2.71e-4, dn/dt = -0.93e-6 /K,
// dn/dp = +2.68e-9 /Pa, dn/df = -3.6e-10 /Pa (tests/plant/fizeau_cavity_test.cpp).
// Real-time safe: no heap, no exceptions.

namespace piezoshift::plant {

struct AirConditions {
  double temperature_C = 20.0;
  double pressure_Pa = 101325.0;
  double water_vapour_pressure_Pa = 0.0;  //!< f, the partial pressure of water vapour
};

//! n - 1 of air at the vacuum wavelength lambda_vac_nm (kept as n - 1: its changes are ~1e-9 of
//! a number near 1).
inline double air_refractivity(double lambda_vac_nm, const AirConditions& air) noexcept {
  const double sigma2 = 1e6 / (lambda_vac_nm * lambda_vac_nm);  // [um^-2]
  const double ns = 1e-8 * (8342.54 + 2406147.0 / (130.0 - sigma2) + 15998.0 / (38.9 - sigma2));
  const double t = air.temperature_C, p = air.pressure_Pa;
  const double ntp =
      p * ns * (1.0 + 1e-8 * (0.601 - 0.00972 * t) * p) / (96095.43 * (1.0 + 0.003661 * t));
  return ntp - air.water_vapour_pressure_Pa * (3.7345 - 0.0401 * sigma2) * 1e-10;
}

}  // namespace piezoshift::plant
