#include "piezoshift/plant/contact.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/core.h>

namespace piezoshift::plant {

double series_stiffness_N_per_um(double actuator_N_per_um, double contact_N_per_um) {
  return 1.0 / (1.0 / actuator_N_per_um + 1.0 / contact_N_per_um);
}

double identify_contact_stiffness_N_per_um(double travel_um, double free_stroke_um,
                                           double actuator_N_per_um, double mechanism_N_per_um) {
  const double r = travel_um / free_stroke_um;
  const double r_max = actuator_N_per_um / (actuator_N_per_um + mechanism_N_per_um);
  if (!(r > 0.0) || !(r < r_max)) {
    throw std::invalid_argument(fmt::format(
        "contact identification: an open-loop travel of {} um needs a free stroke over {} um at "
        "the measurement time (Eq. 1 with a rigid contact gives at most {:.4f} um from {:.4f} um)",
        travel_um, travel_um / r_max, free_stroke_um * r_max, free_stroke_um));
  }
  const double ks = mechanism_N_per_um * r / (1.0 - r);
  return 1.0 / (1.0 / ks - 1.0 / actuator_N_per_um);
}

double hertz_contact_modulus_Pa(double e_Pa, double nu) {
  return e_Pa / (2.0 * (1.0 - nu * nu));
}

double hertz_deflection_um(double force_N, double radius_m, double modulus_Pa) {
  if (!(force_N > 0.0))
    return 0.0;
  return 1e6 * std::cbrt(9.0 * force_N * force_N / (16.0 * modulus_Pa * modulus_Pa * radius_m));
}

double hertz_stiffness_N_per_um(double force_N, double radius_m, double modulus_Pa) {
  return 1e-6 * std::cbrt(6.0 * modulus_Pa * modulus_Pa * radius_m * std::fmax(force_N, 0.0));
}

HertzResidual make_hertz_residual(double preload_N, double radius_m, double modulus_Pa) {
  HertzResidual h;
  h.preload_N = preload_N;
  h.coefficient = 1e6 * std::cbrt(9.0 / (16.0 * modulus_Pa * modulus_Pa * radius_m));
  h.preload_um = hertz_deflection_um(preload_N, radius_m, modulus_Pa);
  h.inv_linear_um_per_N = 1.0 / hertz_stiffness_N_per_um(preload_N, radius_m, modulus_Pa);
  return h;
}

double HertzResidual::operator()(double f_N) const noexcept {
  const double force = preload_N + f_N;
  // past lift-off (F < 0) the linearized spring is all the mechanics has; no residual there
  const double d = force > 0.0 ? coefficient * std::cbrt(force * force) : 0.0;
  return d - preload_um - f_N * inv_linear_um_per_N;
}

namespace {

// x_free needed for a leg displacement x with preload F0.
double hertz_free_stroke_um(double x_um, double ka, double km, double f0, double r, double e) {
  const double f = km * x_um;
  return x_um + f / ka + hertz_deflection_um(f0 + f, r, e) - hertz_deflection_um(f0, r, e);
}

}  // namespace

bool hertz_preload_reachable(double travel_um, double free_stroke_um, double ka, double km,
                             double radius_m, double modulus_Pa) {
  try {
    (void)identify_hertz_preload_N(travel_um, free_stroke_um, ka, km, radius_m, modulus_Pa);
  } catch (const std::invalid_argument&) {
    return false;
  }
  return true;
}

double identify_hertz_preload_N(double travel_um, double free_stroke_um, double ka, double km,
                                double radius_m, double modulus_Pa) {
  // the contact's share of the stroke, d_H(F0 + f) - d_H(F0), falls with F0
  double lo = 1e-6, hi = 1e6;
  const auto excess = [&](double f0) {
    return hertz_free_stroke_um(travel_um, ka, km, f0, radius_m, modulus_Pa) - free_stroke_um;
  };
  if (!(radius_m > 0.0) || !(modulus_Pa > 0.0) || !(excess(lo) > 0.0) || !(excess(hi) < 0.0)) {
    throw std::invalid_argument(fmt::format(
        "Hertz contact identification: no preload between {} and {} N gives an open-loop travel "
        "of {} um from a free stroke of {:.4f} um with a {} m ball",
        lo, hi, travel_um, free_stroke_um, radius_m));
  }
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = std::sqrt(lo * hi);
    (excess(mid) > 0.0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double hertz_static_leg_um(double free_stroke_um, double ka, double km, double f0, double radius_m,
                           double modulus_Pa) {
  double lo = 0.0, hi = free_stroke_um;  // x_free(x) is increasing, x_free(x) >= x
  for (int i = 0; i < 200 && hi - lo > 1e-13; ++i) {
    const double mid = 0.5 * (lo + hi);
    (hertz_free_stroke_um(mid, ka, km, f0, radius_m, modulus_Pa) < free_stroke_um ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace piezoshift::plant
