#pragma once
// The project's configuration file (module `config`, above `plant` whose parameters it reads and
// below `runtime` and everything that builds a twin): one TOML file, one section per parameter
// struct. Every key
// is optional and keeps the struct's default (the paper's value) when absent; configs/paper.toml
// spells out all of them with their sources.
//
//   [actuator]   stiffness_N_per_um, nominal_stroke_um, pushing_force_N, pulling_force_N,
//                capacitance_F, resonance_frequency_Hz, length_m          (Table 1)
//   [material]   elastic_modulus_Pa, poisson_ratio, density_kg_per_m3,
//                allowable_stress_Pa                                       (Table 2)
//   [hinge]      width_m, thickness_m, radius_m, link_length_m             (Table 3)
//   [mechanism]  moving_mass_kg                                            (fitted to Figure 2c)
//
// Every number must be within its range (design/design_ranges.hpp and plant/twin_ranges.hpp,
// the one list the reader, the model builders and the Python bindings share), and the hinge
// buildable (t < 2R, L > 2R). An unknown section or key, a wrong type, a value out of range or a
// syntax error throws core::InputError naming the file, the key and the reason.
#include <string>

#include "piezoshift/design/design_inputs.hpp"
#include "piezoshift/io/config_file.hpp"
#include "piezoshift/plant/twin_params.hpp"

namespace piezoshift::config {

struct ProjectConfig {
  design::DesignInputs design;  //!< [actuator], [material], [hinge], [mechanism]
  plant::TwinParams twin;       //!< [twin] and [twin.<component>] (docs/twin.md)
};

//! Loads a configuration file: reads every section into a ProjectConfig, then rejects any key
//! that no section asked for.
ProjectConfig load_project_config(const std::string& path);

//! Reads [twin] and its [twin.daq], [twin.amplifier], [twin.piezo], [twin.contact],
//! [twin.mechanics], [twin.plate], [twin.geometry], [twin.sgs], [twin.interferometer] and
//! [twin.lab] into twin (absent keys keep its values), with bounds; then checks design and twin
//! together (plant::twin_params_problem: rates that must divide, the contact identification, A).
//! Does not call reject_unknown().
void read_twin_sections(const io::ConfigFile& file, const design::DesignInputs& design,
                        plant::TwinParams& twin);

//! Reads [actuator], [material], [hinge] and [mechanism] into design (absent keys keep its
//! values), with bounds, and checks the hinge geometry. Does not call reject_unknown().
void read_design_sections(const io::ConfigFile& file, design::DesignInputs& design);

}  // namespace piezoshift::config
