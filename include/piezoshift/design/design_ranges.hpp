#pragma once
// The valid range of every design input, in one place: the TOML reader (io/project_config.cpp),
// design_inputs_problem() (and so the Python bindings and evaluate_design) all walk this list.
// The ranges are wide (a design study may go far from the paper) but finite, so every accepted
// value keeps Eqs. 1 to 4 and the twin built on them finite.
//
//   visit_design_values(inputs, [](const char* section, const char* key, auto& value,
//                                  Bounds bounds) { ... });
#include "piezoshift/core/bounds.hpp"
#include "piezoshift/design/design_inputs.hpp"

namespace piezoshift::design {

//! Calls visit(section, key, value, bounds) for each value of inputs (const or not), in the order
//! of configs/paper.toml. section and key are the TOML names ("actuator", "stiffness_N_per_um").
template <typename Inputs, typename Visit>
void visit_design_values(Inputs& in, Visit&& visit) {
  visit("actuator", "stiffness_N_per_um", in.actuator.stiffness_N_per_um,
        core::Bounds::above(0, 1e6));
  visit("actuator", "nominal_stroke_um", in.actuator.nominal_stroke_um,
        core::Bounds::above(0, 1e4));
  visit("actuator", "pushing_force_N", in.actuator.pushing_force_N, core::Bounds::above(0, 1e7));
  visit("actuator", "pulling_force_N", in.actuator.pulling_force_N, core::Bounds::above(0, 1e7));
  visit("actuator", "capacitance_F", in.actuator.capacitance_F, core::Bounds::above(0, 1.0));
  visit("actuator", "resonance_frequency_Hz", in.actuator.resonance_frequency_Hz,
        core::Bounds::above(0, 1e8));
  visit("actuator", "length_m", in.actuator.length_m, core::Bounds::above(0, 10.0));
  visit("material", "elastic_modulus_Pa", in.material.elastic_modulus_Pa,
        core::Bounds::above(0, 1e13));
  visit("material", "poisson_ratio", in.material.poisson_ratio, core::Bounds::open(0.0, 0.5));
  visit("material", "density_kg_per_m3", in.material.density_kg_per_m3,
        core::Bounds::above(0, 1e5));
  visit("material", "allowable_stress_Pa", in.material.allowable_stress_Pa,
        core::Bounds::above(0, 1e11));
  visit("hinge", "width_m", in.hinge.width_m, core::Bounds::above(0, 1.0));
  visit("hinge", "thickness_m", in.hinge.thickness_m, core::Bounds::above(0, 1.0));
  visit("hinge", "radius_m", in.hinge.radius_m, core::Bounds::above(0, 1.0));
  visit("hinge", "link_length_m", in.hinge.link_length_m, core::Bounds::above(0, 10.0));
  visit("mechanism", "moving_mass_kg", in.mechanism.moving_mass_kg, core::Bounds::above(0, 1e4));
}

}  // namespace piezoshift::design
