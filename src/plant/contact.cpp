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

}  // namespace piezoshift::plant
