#include "piezoshift/tolerance/tolerance_file.hpp"

#include "piezoshift/plant/twin_model.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <optional>
#include <type_traits>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/design/design_ranges.hpp"
#include "piezoshift/io/config_file.hpp"
#include "piezoshift/io/input_file.hpp"
#include "piezoshift/plant/twin_model.hpp"
#include "piezoshift/plant/twin_ranges.hpp"

namespace piezoshift::tolerance {
namespace {

// A truncated normal below a tenth of sigma rejects more than 92 % of its draws: ask for uniform.
constexpr double kMinBoundOverSigma = 0.1;
constexpr std::size_t kMaxDiscreteValues = 64;

template <class Config, class Visit>
void visit_parameters(Config& c, Visit&& visit) {
  design::visit_design_values(c.design, visit);
  plant::visit_twin_values(c.twin, visit);
}

std::uint64_t splitmix64(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Uniform in [0, 1) from the top 53 bits: the same on every platform (std's distributions are not).
double unit(std::uint64_t& state) {
  return static_cast<double>(splitmix64(state) >> 11) * 0x1.0p-53;
}

double draw(const Distribution& d, std::uint64_t& state) {
  switch (d.kind) {
    case DistributionKind::kUniform:
      return d.lo + (d.hi - d.lo) * unit(state);
    case DistributionKind::kNormal:
      while (true) {  // Box-Muller, rejected outside +-bound (accepts >= 8 %: kMinBoundOverSigma)
        const double u1 = 1.0 - unit(state);  // (0, 1]
        const double u2 = unit(state);
        const double z =
            std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2) * d.sigma;
        if (std::abs(z) <= d.bound)
          return z;
      }
    case DistributionKind::kDiscrete:
      return d.values[static_cast<std::size_t>(unit(state) * static_cast<double>(d.values.size()))];
  }
  return 0.0;
}

[[noreturn]] void refuse(const std::string& source, const std::string& section,
                         const std::string& why) {
  throw core::InputError(fmt::format("{}: [{}]: {}", source, section, why));
}

Distribution read_distribution(const io::ConfigSection& s, const std::string& source) {
  Distribution d;
  std::string kind;
  if (!s.read("distribution", kind))
    refuse(source, s.name(), "distribution missing (uniform, normal or discrete)");
  s.read("relative", d.relative);
  const auto need = [&](const char* key, double& v) {
    if (!s.read(key, v))
      refuse(source, s.name(), fmt::format("{} distribution needs {}", kind, key));
  };
  if (kind == "uniform") {
    d.kind = DistributionKind::kUniform;
    need("lo", d.lo);
    need("hi", d.hi);
    if (d.lo > d.hi)
      refuse(source, s.name(), fmt::format("cannot be sampled: lo {} > hi {}", d.lo, d.hi));
  } else if (kind == "normal") {
    d.kind = DistributionKind::kNormal;
    need("sigma", d.sigma);
    need("bound", d.bound);
    if (!(d.sigma > 0.0) || !(d.bound >= kMinBoundOverSigma * d.sigma))
      refuse(source, s.name(),
             fmt::format("cannot be sampled: needs sigma > 0 and bound >= {} sigma (sigma {}, "
                         "bound {}); a narrower one is a uniform",
                         kMinBoundOverSigma, d.sigma, d.bound));
  } else if (kind == "discrete") {
    d.kind = DistributionKind::kDiscrete;
    if (!s.read("values", d.values, kMaxDiscreteValues))
      refuse(source, s.name(), "discrete distribution needs values = [...]");
  } else {
    refuse(
        source, s.name(),
        fmt::format("distribution = \"{}\" cannot be sampled: uniform, normal or discrete", kind));
  }
  return d;
}

void check_range(const Tolerance& t, const std::string& source, const std::string& section) {
  if (t.distribution.relative && t.nominal == 0.0)
    refuse(source, section,
           fmt::format("relative deviations of {} (nominal 0) would vary nothing: give them in "
                       "the key's unit",
                       t.key));
  for (const double dev : {t.distribution.min_deviation(), t.distribution.max_deviation()}) {
    const std::string problem = core::range_problem(t.key, t.value_at(dev), t.bounds);
    if (!problem.empty())
      refuse(source, section,
             fmt::format("{} reaches outside the parameter's valid range (nominal {}): {}",
                         t.distribution.describe(), t.nominal, problem));
  }
}

}  // namespace

double Distribution::min_deviation() const {
  switch (kind) {
    case DistributionKind::kUniform:
      return lo;
    case DistributionKind::kNormal:
      return -bound;
    case DistributionKind::kDiscrete:
      return *std::min_element(values.begin(), values.end());
  }
  return 0.0;
}

double Distribution::max_deviation() const {
  switch (kind) {
    case DistributionKind::kUniform:
      return hi;
    case DistributionKind::kNormal:
      return bound;
    case DistributionKind::kDiscrete:
      return *std::max_element(values.begin(), values.end());
  }
  return 0.0;
}

std::string Distribution::describe() const {
  std::string s;
  switch (kind) {
    case DistributionKind::kUniform:
      s = fmt::format("uniform [{:g}, {:g}]", lo, hi);
      break;
    case DistributionKind::kNormal:
      s = fmt::format("normal sigma {:g} bound ±{:g}", sigma, bound);
      break;
    case DistributionKind::kDiscrete: {
      s = "discrete {";
      for (std::size_t i = 0; i < values.size(); ++i)
        s += fmt::format("{}{:g}", i ? ", " : "", values[i]);
      s += "}";
      break;
    }
  }
  return relative ? s + " (relative)" : s;
}

double Tolerance::value_at(double deviation) const {
  return distribution.relative ? nominal * (1.0 + deviation) : nominal + deviation;
}

double* parameter_slot(config::ProjectConfig& config, std::string_view key, core::Bounds* bounds) {
  double* out = nullptr;
  visit_parameters(config, [&](const char* section, const char* name, auto& value, core::Bounds b) {
    using T = std::decay_t<decltype(value)>;
    const std::string base = fmt::format("{}.{}", section, name);
    double* slot = nullptr;
    if constexpr (std::is_same_v<T, double>) {
      if (key == base)
        slot = &value;
    } else if constexpr (std::is_same_v<T, std::array<double, 3>>) {
      for (std::size_t i = 0; i < value.size(); ++i)
        if (key == fmt::format("{}[{}]", base, i))
          slot = &value[i];
    } else if constexpr (std::is_same_v<T, std::optional<double>>) {
      if (key == base && value.has_value())
        slot = &*value;
    }
    if (slot != nullptr) {
      out = slot;
      if (bounds != nullptr)
        *bounds = b;
    }
  });
  return out;
}

ToleranceSet parse_tolerances(std::string_view text, const std::string& source_name,
                              const config::ProjectConfig& nominal) {
  const io::ConfigFile file = io::ConfigFile::parse(text, source_name);
  ToleranceSet set;
  set.source_name = source_name;
  config::ProjectConfig probe = nominal;
  // Each parameter of the range lists is asked for its section; reject_unknown() then names any
  // tolerance on a parameter that does not exist.
  std::vector<std::string> keys;
  visit_parameters(probe, [&](const char* section, const char* name, auto& value, core::Bounds) {
    const std::string base = fmt::format("{}.{}", section, name);
    const io::ConfigSection s = file.section("tolerance." + base);
    if (!s.has("distribution") && !s.has("source"))
      return;
    using T = std::decay_t<decltype(value)>;
    if constexpr (std::is_same_v<T, std::array<double, 3>>) {
      for (std::size_t i = 0; i < value.size(); ++i)
        keys.push_back(fmt::format("{}[{}]", base, i));
    } else if constexpr (std::is_same_v<T, double> || std::is_same_v<T, std::optional<double>>) {
      keys.push_back(base);
    } else {
      refuse(source_name, s.name(), "not a number with a tolerance (an integer or a matrix)");
    }
    const Distribution d = read_distribution(s, source_name);
    std::string src;
    if (!s.read("source", src) || src.empty())
      refuse(source_name, s.name(),
             "source missing: say where the tolerance comes from (or "
             "that it is an assumption)");
    for (const std::string& key : keys) {
      Tolerance t;
      t.key = key;
      t.distribution = d;
      t.source = src;
      const double* slot = parameter_slot(probe, key, &t.bounds);
      if (slot == nullptr)
        refuse(source_name, s.name(), "has no nominal value in the configuration to vary");
      t.nominal = *slot;
      check_range(t, source_name, s.name());
      set.tolerances.push_back(std::move(t));
    }
    keys.clear();
  });
  file.reject_unknown();
  if (set.tolerances.empty())
    throw core::InputError(fmt::format("{}: no [tolerance.<parameter>] section", source_name));
  return set;
}

std::string pin_identified_contact(config::ProjectConfig& config) {
  const plant::TwinModel m = plant::make_twin_model(config.design, config.twin);
  if (m.contact_preload_identified) {
    config.twin.contact.preload_N = m.contact_preload_N;
    return fmt::format("twin.contact.preload_N = {} (identified)", m.contact_preload_N);
  }
  if (m.contact_identified && !m.contact_hertz) {
    config.twin.contact.stiffness_N_per_um = m.contact_stiffness_N_per_um;
    return fmt::format("twin.contact.stiffness_N_per_um = {} (identified)",
                       m.contact_stiffness_N_per_um);
  }
  return "";
}

ToleranceSet load_tolerances(const std::string& path, const config::ProjectConfig& nominal) {
  return parse_tolerances(io::read_input_file(path, io::kMaxConfigFileBytes), path, nominal);
}

std::vector<double> draw_deviations(const ToleranceSet& set, std::uint64_t seed,
                                    std::uint64_t index) {
  std::vector<double> out;
  for (std::size_t i = 0; i < set.tolerances.size(); ++i) {
    std::uint64_t state = seed;
    state = splitmix64(state) ^ (index * 0xd1b54a32d192ed03ULL);
    state = splitmix64(state) ^ (static_cast<std::uint64_t>(i) * 0x8cb92ba72f3d8dd7ULL);
    out.push_back(draw(set.tolerances[i].distribution, state));
  }
  return out;
}

std::string apply_deviations(const ToleranceSet& set, const std::vector<double>& deviations,
                             config::ProjectConfig& config) {
  for (std::size_t i = 0; i < set.tolerances.size(); ++i) {
    const Tolerance& t = set.tolerances[i];
    double* slot = parameter_slot(config, t.key, nullptr);
    if (slot == nullptr)
      return fmt::format("{}: not in the configuration", t.key);
    *slot = t.value_at(deviations.at(i));
    const std::string problem = core::range_problem(t.key, *slot, t.bounds);
    if (!problem.empty())
      return problem;
  }
  std::string problem = design::design_inputs_problem(config.design);
  if (problem.empty())
    problem = plant::twin_params_problem(config.design, config.twin);
  return problem;
}

}  // namespace piezoshift::tolerance
