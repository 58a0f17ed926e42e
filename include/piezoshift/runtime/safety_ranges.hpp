#pragma once
// The valid range of every safety limit, in one place, and the [safety] section of an
// installation's configuration file that sets them (docs/safety.md lists each limit, its default
// and its range). SafetySupervisor::configure(), the TOML reader and the commands that print the
// limits all use this list.
//
//   [safety]
//   output_max_V = 8.0          # this stage: 120 V at the stacks
//   max_consecutive_overruns = 5
#include <cstdint>
#include <string>
#include <string_view>

#include "piezoshift/config/project_config.hpp"
#include "piezoshift/core/bounds.hpp"
#include "piezoshift/io/config_file.hpp"
#include "piezoshift/runtime/safety_supervisor.hpp"

namespace piezoshift::runtime {

//! Largest max_consecutive_overruns (and --max-overruns): a million in a row, 17 min at 1 kHz, is
//! "never".
inline constexpr std::uint32_t kMaxConsecutiveOverruns = 1000000;

//! Calls visit(section, key, value, bounds) for each limit (const or not); value is a double or
//! a std::uint32_t (the overrun count, trip_on_overruns, oscillation_reversals). The ranges keep
//! every rule meaningful: the outputs within the
//! +-10 V a DAQ writes, times from one tick to a minute.
template <typename Limits, typename Visit>
void visit_safety_limits(Limits& l, Visit&& visit) {
  using B = core::Bounds;
  visit("safety", "output_min_V", l.output_min_V, B::closed(-10.0, 0.0));
  visit("safety", "output_max_V", l.output_max_V, B::above(0.0, 10.0));
  visit("safety", "max_slew_V_per_s", l.max_slew_V_per_s, B::above(0.0, 1e6));
  visit("safety", "safe_ramp_V_per_s", l.safe_ramp_V_per_s, B::above(0.0, 1e6));
  visit("safety", "sgs_min_V", l.sgs_min_V, B::closed(-10.0, 10.0));
  visit("safety", "sgs_max_V", l.sgs_max_V, B::closed(-10.0, 10.0));
  visit("safety", "adc_full_scale_V", l.adc_full_scale_V, B::above(0.0, 10.0));
  visit("safety", "rail_margin_V", l.rail_margin_V, B::closed(0.0, 1.0));
  visit("safety", "sgs_noise_V", l.sgs_noise_V, B::closed(0.0, 10.0));
  visit("safety", "jump_factor", l.jump_factor, B::closed(2.0, 100.0));
  visit("safety", "stage_gain", l.stage_gain, B::above(0.0, 10.0));
  visit("safety", "tracking_error_um", l.tracking_error_um, B::above(0.0, 100.0));
  visit("safety", "tracking_time_s", l.tracking_time_s, B::above(0.0, 60.0));
  visit("safety", "response_gain_min", l.response_gain_min, B::closed(0.0, 10.0));
  visit("safety", "response_gain_max", l.response_gain_max, B::above(0.0, 10.0));
  visit("safety", "response_band_um", l.response_band_um, B::closed(0.0, 100.0));
  visit("safety", "response_time_s", l.response_time_s, B::above(0.0, 60.0));
  visit("safety", "saturation_time_s", l.saturation_time_s, B::above(0.0, 60.0));
  visit("safety", "max_consecutive_overruns", l.max_consecutive_overruns,
        B::closed(1, kMaxConsecutiveOverruns));
  visit("safety", "trip_on_overruns", l.trip_on_overruns,
        B::closed(kOverrunTripNever, kOverrunTripOnHardware));
  visit("safety", "oscillation_band_um", l.oscillation_band_um, B::above(0.0, 100.0));
  visit("safety", "oscillation_reversals", l.oscillation_reversals,
        B::closed(2, kMaxOscillationReversals));
  visit("safety", "oscillation_time_s", l.oscillation_time_s, B::above(0.0, 60.0));
}

//! The first limit outside its range, or a pair that contradicts itself (output_min_V <
//! output_max_V, safe_ramp_V_per_s <= max_slew_V_per_s, sgs_min_V < sgs_max_V,
//! response_gain_min < response_gain_max); "" when the limits are consistent.
std::string safety_limits_problem(const SafetyLimits& limits);

//! Reads [safety] into limits (absent keys keep their values), with the ranges above, then checks
//! the pairs; InputError naming the file (and line and key) otherwise. Does not call
//! reject_unknown().
void read_safety_section(const io::ConfigFile& file, SafetyLimits& limits);

//! trip_on_overruns resolved for the backend: "on hardware" becomes never on the twin (a late
//! host does not hurt a simulated stage: its overruns are counted and reported) and always on a
//! board; never and always stay.
SafetyLimits resolve_overrun_trip(SafetyLimits limits, bool twin);

//! One installation's configuration: the design and twin sections and [safety].
struct InstallationConfig {
  config::ProjectConfig project;
  SafetyLimits safety;
};

//! Loads a configuration file as config::load_project_config() does, with [safety] besides.
InstallationConfig load_installation_config(const std::string& path);
//! The same from a file's text (a worker given the text of a file it has not: tolerance studies).
InstallationConfig parse_installation_config(std::string_view text, const std::string& source_name);

//! One line for start-up summaries: every limit with its unit.
std::string describe(const SafetyLimits& limits);

}  // namespace piezoshift::runtime
