#pragma once
// Tolerances as data: a TOML file naming parameters of the design and the twin by
// their configuration keys, each with a distribution of its deviation from the nominal value and
// the source of that tolerance (docs/tolerance.md):
//
//   [tolerance.hinge.thickness_m]
//   distribution = "uniform"     # lo, hi: the deviation, in the key's unit
//   lo = -5e-6
//   hi = 5e-6
//   source = "wire EDM, +-5 um (workshop quote)"
//
//   [tolerance.twin.piezo.free_stroke_scale]   # a per-leg list: each leg drawn on its own
//   distribution = "normal"      # sigma, bound: truncated at +-bound
//   sigma = 0.02
//   bound = 0.05
//   relative = true              # deviations as fractions of the nominal value
//   source = "..."
//
//   distribution = "discrete"    # values = [...]: one of them, each equally likely
//
// Any number of the two range lists (design/design_ranges.hpp, plant/twin_ranges.hpp) is a
// parameter: a number, one leg of a three-element list (key[0..2]), or an optional that has a
// value. Refused with core::InputError naming the key: an unknown parameter (or key), a parameter
// that is not a number, a nominal +- the distribution's extremes outside the parameter's valid
// range, a distribution that cannot be sampled, a missing source.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "piezoshift/config/project_config.hpp"
#include "piezoshift/core/bounds.hpp"

namespace piezoshift::tolerance {

enum class DistributionKind { kUniform, kNormal, kDiscrete };

struct Distribution {
  DistributionKind kind = DistributionKind::kUniform;
  double lo = 0.0, hi = 0.0;        //!< uniform
  double sigma = 0.0, bound = 0.0;  //!< normal, truncated at +-bound
  std::vector<double> values;       //!< discrete
  bool relative = false;            //!< deviations are fractions of the nominal value

  double min_deviation() const;
  double max_deviation() const;
  //! "uniform [-5e-06, 5e-06]", "normal sigma 0.02 bound 0.05 (relative)", ...
  std::string describe() const;
};

//! One drawn element: a number of the configuration, or one leg of a per-leg list.
struct Tolerance {
  std::string key;  //!< "hinge.thickness_m" or "twin.piezo.free_stroke_scale[1]"
  Distribution distribution;
  std::string source;
  double nominal = 0.0;
  core::Bounds bounds;

  //! The parameter's value for a deviation d (nominal + d, or nominal (1 + d) when relative).
  double value_at(double deviation) const;
};

struct ToleranceSet {
  std::string source_name;            //!< the file
  std::vector<Tolerance> tolerances;  //!< in the order of the range lists, legs in order
};

//! The value slot of a parameter of config by key (see above), with its valid range; nullptr when
//! no number of the range lists has that key (or it is an optional without a value).
double* parameter_slot(config::ProjectConfig& config, std::string_view key, core::Bounds* bounds);

//! The nominal stage's contact as a built stage has it. Unless the configuration gives it, the twin
//! identifies the contact (its preload, or a linear stiffness) from the open-loop travel and the
//! stacks' mean stroke; a sample with other stacks would then be given another contact, softer for
//! stronger stacks, so that its open-loop travel stays the paper's. A built stage keeps its set
//! screw's preload whatever its stacks: this sets the identified value into the configuration
//! (twin.contact.preload_N, or stiffness_N_per_um for a linear contact), which also makes it a
//! parameter a tolerance can name. Returns what it set ("" when the configuration gave it).
std::string pin_identified_contact(config::ProjectConfig& config);

//! Parses a tolerance file against the nominal configuration. Throws core::InputError.
ToleranceSet load_tolerances(const std::string& path, const config::ProjectConfig& nominal);
ToleranceSet parse_tolerances(std::string_view text, const std::string& source_name,
                              const config::ProjectConfig& nominal);

//! The deviations of sample `index` of a study with `seed`: one per tolerance, each from its own
//! stream (seed, index, tolerance position), so a sample is the same whichever process draws it.
std::vector<double> draw_deviations(const ToleranceSet& set, std::uint64_t seed,
                                    std::uint64_t index);

//! config with each tolerance's value for deviations[i]; "" or the problem that makes the plant
//! unbuildable (design_inputs_problem, twin_params_problem), named.
std::string apply_deviations(const ToleranceSet& set, const std::vector<double>& deviations,
                             config::ProjectConfig& config);

}  // namespace piezoshift::tolerance
