#pragma once
// Every parameter of the digital twin, one value struct per component (each header states its
// equations and the source of each default). The design's own numbers (actuator stiffness,
// stroke, capacitance and resonance; mechanism stiffness from Eqs. 2-3 and moving mass; the
// material) are not repeated here: the twin takes them from design::DesignInputs.
// configs/paper.toml spells all of them out under [twin] and [twin.<component>].
#include <string>

#include "piezoshift/design/design_inputs.hpp"
#include "piezoshift/plant/amplifier.hpp"
#include "piezoshift/plant/contact.hpp"
#include "piezoshift/plant/daq.hpp"
#include "piezoshift/plant/fizeau_cavity.hpp"
#include "piezoshift/plant/geometry.hpp"
#include "piezoshift/plant/interferometer.hpp"
#include "piezoshift/plant/lab_environment.hpp"
#include "piezoshift/plant/mechanics.hpp"
#include "piezoshift/plant/piezo_stack.hpp"
#include "piezoshift/plant/plate.hpp"
#include "piezoshift/plant/sgs.hpp"

namespace piezoshift::plant {

struct TwinParams {
  //! Physics rate: amplifier, hysteresis, mechanics and conditioner filter are stepped at
  //! 1 / physics_rate_Hz; it must be a whole multiple of the DAQ's (control) rate.
  double physics_rate_Hz = 20000.0;
  DaqParams daq{};
  AmplifierParams amplifier{};
  PiezoParams piezo{};
  ContactParams contact{};
  MechanicsParams mechanics{};
  PlateParams plate{};
  GeometryParams geometry{};
  SgsParams sgs{};
  InterferometerParams interferometer{};
  LabParams lab{};
  CavityParams cavity{};

  bool operator==(const TwinParams&) const = default;
};

//! Why design and twin parameters cannot make a twin, or "" when they can: the checks a single
//! value's bounds cannot express (rates that must divide each other, the contact identification's
//! limit, A's factorization, ...). It builds the twin's model to find out.
std::string twin_params_problem(const design::DesignInputs& design, const TwinParams& twin);

}  // namespace piezoshift::plant
