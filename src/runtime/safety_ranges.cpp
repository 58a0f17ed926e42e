#include "piezoshift/runtime/safety_ranges.hpp"
#include "piezoshift/core/bounds.hpp"

#include <type_traits>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"

namespace piezoshift::runtime {

std::string safety_limits_problem(const SafetyLimits& l) {
  std::string problem;
  visit_safety_limits(
      l, [&](const char* section, const char* key, const auto& value, core::Bounds bounds) {
        if (problem.empty()) {
          problem = core::range_problem(fmt::format("{}.{}", section, key),
                                        static_cast<double>(value), bounds);
        }
      });
  if (!problem.empty())
    return problem;
  if (!(l.output_min_V < l.output_max_V))
    return fmt::format("safety.output_min_V = {} must be below safety.output_max_V = {}",
                       l.output_min_V, l.output_max_V);
  if (!(l.safe_ramp_V_per_s <= l.max_slew_V_per_s))
    return fmt::format("safety.safe_ramp_V_per_s = {} must not exceed safety.max_slew_V_per_s = {}",
                       l.safe_ramp_V_per_s, l.max_slew_V_per_s);
  if (!(l.sgs_min_V < l.sgs_max_V))
    return fmt::format("safety.sgs_min_V = {} must be below safety.sgs_max_V = {}", l.sgs_min_V,
                       l.sgs_max_V);
  if (!(l.response_gain_min < l.response_gain_max))
    return fmt::format("safety.response_gain_min = {} must be below safety.response_gain_max = {}",
                       l.response_gain_min, l.response_gain_max);
  return {};
}

void read_safety_section(const io::ConfigFile& file, SafetyLimits& limits) {
  const io::ConfigSection s = file.section("safety");
  visit_safety_limits(limits, [&](const char*, const char* key, auto& value, core::Bounds bounds) {
    if constexpr (std::is_same_v<std::remove_reference_t<decltype(value)>, std::uint32_t>) {
      if (std::int64_t v = 0; s.read(key, v, bounds))
        value = static_cast<std::uint32_t>(v);  // within bounds, so within uint32
    } else {
      s.read(key, value, bounds);
    }
  });
  if (const std::string problem = safety_limits_problem(limits); !problem.empty())
    throw core::InputError(fmt::format("{}: {}", file.source(), problem));
}

namespace {

InstallationConfig read_installation_config(const io::ConfigFile& file) {
  InstallationConfig c;
  config::read_design_sections(file, c.project.design);
  config::read_twin_sections(file, c.project.design, c.project.twin);
  read_safety_section(file, c.safety);
  file.reject_unknown();
  return c;
}

}  // namespace

InstallationConfig load_installation_config(const std::string& path) {
  return read_installation_config(io::ConfigFile::load(path));
}

InstallationConfig parse_installation_config(std::string_view text,
                                             const std::string& source_name) {
  return read_installation_config(io::ConfigFile::parse(text, source_name));
}

std::string describe(const SafetyLimits& l) {
  return fmt::format(
      "outputs {} to {} V, slew {} V/s (stop ramp {} V/s), SGS {} to {} V (rail within {} V of "
      "{} V, jump {} x slew + {} V), tracking {} um for {} s, response {} to {} +- {} um for {} "
      "s, saturation {} s, {} overruns in a row{}, oscillation {} reversals of {} um in {} s",
      l.output_min_V, l.output_max_V, l.max_slew_V_per_s, l.safe_ramp_V_per_s, l.sgs_min_V,
      l.sgs_max_V, l.rail_margin_V, l.adc_full_scale_V, l.jump_factor, l.sgs_noise_V,
      l.tracking_error_um, l.tracking_time_s, l.response_gain_min, l.response_gain_max,
      l.response_band_um, l.response_time_s, l.saturation_time_s, l.max_consecutive_overruns,
      l.trip_on_overruns == kOverrunTripNever        ? " (counted, no trip)"
      : l.trip_on_overruns == kOverrunTripOnHardware ? " (trip on hardware)"
                                                     : "",
      l.oscillation_reversals, l.oscillation_band_um, l.oscillation_time_s);
}

SafetyLimits resolve_overrun_trip(SafetyLimits limits, bool twin) {
  if (limits.trip_on_overruns == kOverrunTripOnHardware)
    limits.trip_on_overruns = twin ? kOverrunTripNever : kOverrunTripAlways;
  return limits;
}

}  // namespace piezoshift::runtime
