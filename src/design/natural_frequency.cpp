#include "piezoshift/design/natural_frequency.hpp"

#include <cmath>
#include <numbers>

namespace piezoshift::design {

double natural_frequency_Hz(double stiffness_N_per_um, double moving_mass_kg) {
  return std::sqrt(stiffness_N_per_um * 1e6 / moving_mass_kg) / (2.0 * std::numbers::pi);
}

}  // namespace piezoshift::design
