#include "piezoshift/tolerance/tolerance_summary.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/config_file.hpp"
#include "piezoshift/io/input_file.hpp"

namespace piezoshift::tolerance {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// NaN (not measured) is JSON's null; infinity (a step that never settled) a string.
nlohmann::json number(double v) {
  if (std::isnan(v))
    return nullptr;
  if (std::isinf(v))
    return v > 0 ? "inf" : "-inf";
  return v;
}

double from_number(const nlohmann::json& j) {
  if (j.is_null())
    return kNaN;
  if (j.is_string())
    return j.get<std::string>() == "-inf" ? -kInf : kInf;
  return j.get<double>();
}

std::string cell(double v) {
  return std::isnan(v) ? std::string() : fmt::format("{}", v);
}

// The change of a metric over its nominal value, in %.
double change_pct(double v, double nominal) {
  if (!std::isfinite(v) || !std::isfinite(nominal) || nominal == 0.0)
    return kNaN;
  return 100.0 * (v - nominal) / std::abs(nominal);
}

// What the calibration changed to absorb a deviation: the largest |change| of an element of A
// (absolute: some elements are near 0) and the change of p(6 um) in %.
nlohmann::json compensator_change(const SampleResult& s, const SampleResult& nominal) {
  const std::size_t p = compensators().size() - 1;
  double a = kNaN;
  for (std::size_t i = 0; i < p; ++i) {
    const double d = std::abs(s.compensators.at(i) - nominal.compensators.at(i));
    if (std::isfinite(d))
      a = std::isnan(a) ? d : std::max(a, d);
  }
  return {
      {"A_max_abs_change", number(a)},
      {"p_6um_change_pct", number(change_pct(s.compensators.at(p), nominal.compensators.at(p)))}};
}

}  // namespace

bool Spec::empty() const {
  for (std::size_t i = 0; i < min.size(); ++i)
    if (std::isfinite(min[i]) || std::isfinite(max[i]))
      return false;
  return true;
}

Spec parse_spec(std::string_view text, const std::string& source_name) {
  const io::ConfigFile file = io::ConfigFile::parse(text, source_name);
  const io::ConfigSection s = file.section("spec");
  Spec spec;
  spec.source = source_name;
  spec.min.assign(metrics().size(), -kInf);
  spec.max.assign(metrics().size(), kInf);
  for (std::size_t i = 0; i < metrics().size(); ++i) {
    s.read(fmt::format("{}_min", metrics()[i].key), spec.min[i]);
    s.read(fmt::format("{}_max", metrics()[i].key), spec.max[i]);
    if (spec.min[i] > spec.max[i])
      throw core::InputError(fmt::format("{}: [spec] {}_min {} is above {}_max {}", source_name,
                                         metrics()[i].key, spec.min[i], metrics()[i].key,
                                         spec.max[i]));
  }
  file.reject_unknown();
  return spec;
}

Spec load_spec(const std::string& path) {
  return parse_spec(io::read_input_file(path, io::kMaxConfigFileBytes), path);
}

double spec_margin(const Spec& spec, const SampleResult& sample) {
  double m = kInf;
  for (std::size_t i = 0; i < spec.min.size(); ++i) {
    const bool bounded = std::isfinite(spec.min[i]) || std::isfinite(spec.max[i]);
    if (!bounded)
      continue;
    const double v = sample.metrics.at(i);
    if (!sample.valid || std::isnan(v))
      return -kInf;
    if (std::isfinite(spec.min[i]))
      m = std::min(m, (v - spec.min[i]) / std::max(std::abs(spec.min[i]), 1e-300));
    if (std::isfinite(spec.max[i]))
      m = std::min(m, (spec.max[i] - v) / std::max(std::abs(spec.max[i]), 1e-300));
  }
  if (!sample.valid)
    return -kInf;  // a failed sample fails the spec, whatever the spec bounds
  return m;
}

std::string spec_failure(const Spec& spec, const SampleResult& sample) {
  if (!sample.valid)
    return "not valid: " + sample.reason;
  for (std::size_t i = 0; i < spec.min.size(); ++i) {
    const double v = sample.metrics.at(i);
    const char* key = metrics()[i].key;
    const bool bounded = std::isfinite(spec.min[i]) || std::isfinite(spec.max[i]);
    if (bounded && std::isnan(v))
      return fmt::format("{} not measured", key);
    if (v < spec.min[i])
      return fmt::format("{} = {:.6g} < {:g}", key, v, spec.min[i]);
    if (v > spec.max[i])
      return fmt::format("{} = {:.6g} > {:g}", key, v, spec.max[i]);
  }
  return "";
}

nlohmann::json study_header(const ToleranceSet& set, const StudyOptions& options,
                            std::uint64_t samples) {
  nlohmann::json tol = nlohmann::json::array();
  for (const Tolerance& t : set.tolerances)
    tol.push_back({{"key", t.key},
                   {"nominal", t.nominal},
                   {"distribution", t.distribution.describe()},
                   {"source", t.source}});
  nlohmann::json m = nlohmann::json::array();
  for (const Metric& x : metrics())
    m.push_back(x.key);
  return {{"seed", options.seed},
          {"procedure", procedure_name(options.procedure)},
          {"experiments", experiment_set_name(options.experiments)},
          {"samples", samples},
          {"tolerances", tol},
          {"metrics", m}};
}

nlohmann::json sample_json(const ToleranceSet& set, const SampleResult& s) {
  nlohmann::json dev = nlohmann::json::object(), val = nlohmann::json::object(),
                 met = nlohmann::json::object();
  for (std::size_t i = 0; i < set.tolerances.size(); ++i) {
    dev[set.tolerances[i].key] = s.deviations.at(i);
    val[set.tolerances[i].key] = set.tolerances[i].value_at(s.deviations.at(i));
  }
  for (std::size_t i = 0; i < metrics().size(); ++i)
    met[metrics()[i].key] = number(s.metrics.at(i));
  nlohmann::json cal = nlohmann::json::object();
  for (std::size_t i = 0; i < compensators().size(); ++i)
    cal[compensators()[i].key] = i < s.compensators.size() ? number(s.compensators[i]) : nullptr;
  return {{"index", s.index}, {"valid", s.valid}, {"reason", s.reason}, {"deviations", dev},
          {"values", val},    {"metrics", met},   {"calibration", cal}};
}

SampleResult sample_from_json(const ToleranceSet& set, const nlohmann::json& j,
                              const std::string& source) {
  try {
    SampleResult s;
    s.index = j.at("index").get<std::uint64_t>();
    s.valid = j.at("valid").get<bool>();
    s.reason = j.at("reason").get<std::string>();
    for (const Tolerance& t : set.tolerances)
      s.deviations.push_back(j.at("deviations").at(t.key).get<double>());
    for (const Metric& m : metrics())
      s.metrics.push_back(from_number(j.at("metrics").at(m.key)));
    for (const Compensator& c : compensators())
      s.compensators.push_back(from_number(j.at("calibration").at(c.key)));
    return s;
  } catch (const nlohmann::json::exception& e) {
    throw core::InputError(fmt::format("{}: not a sample of this study: {}", source, e.what()));
  }
}

nlohmann::json study_json(const ToleranceSet& set, const nlohmann::json& header, const Spec& spec,
                          const std::vector<SampleResult>& samples, std::size_t worst_count) {
  nlohmann::json out{{"study", header}};
  nlohmann::json bounds = nlohmann::json::object();
  for (std::size_t i = 0; i < spec.min.size(); ++i) {
    if (std::isfinite(spec.min[i]))
      bounds[std::string(metrics()[i].key) + "_min"] = spec.min[i];
    if (std::isfinite(spec.max[i]))
      bounds[std::string(metrics()[i].key) + "_max"] = spec.max[i];
  }
  out["spec"] = bounds;
  std::size_t pass = 0, valid = 0;
  for (const SampleResult& s : samples) {
    valid += s.valid ? 1 : 0;
    pass += spec_failure(spec, s).empty() ? 1 : 0;
  }
  out["yield"] = {{"samples", samples.size()},
                  {"valid", valid},
                  {"pass", pass},
                  {"fraction", samples.empty() ? 0.0 : double(pass) / double(samples.size())}};
  std::vector<const SampleResult*> order;
  for (const SampleResult& s : samples)
    order.push_back(&s);
  std::stable_sort(order.begin(), order.end(), [&](const SampleResult* a, const SampleResult* b) {
    return spec_margin(spec, *a) < spec_margin(spec, *b);
  });
  nlohmann::json worst = nlohmann::json::array();
  for (std::size_t i = 0; i < std::min(worst_count, order.size()); ++i) {
    nlohmann::json w = sample_json(set, *order[i]);
    w["spec_failure"] = spec_failure(spec, *order[i]);
    w["spec_margin"] = number(spec_margin(spec, *order[i]));
    worst.push_back(std::move(w));
  }
  out["worst"] = worst;
  nlohmann::json all = nlohmann::json::array();
  for (const SampleResult& s : samples)
    all.push_back(sample_json(set, s));
  out["samples"] = all;
  return out;
}

std::string study_csv(const ToleranceSet& set, const Spec& spec,
                      const std::vector<SampleResult>& samples) {
  std::string out = "index,valid,pass";
  for (const Tolerance& t : set.tolerances)
    out += "," + t.key;
  for (const Metric& m : metrics())
    out += fmt::format(",{}", m.key);
  out += ",reason\n";
  for (const SampleResult& s : samples) {
    out += fmt::format("{},{},{}", s.index, s.valid ? 1 : 0, spec_failure(spec, s).empty() ? 1 : 0);
    for (std::size_t i = 0; i < set.tolerances.size(); ++i)
      out += "," + cell(set.tolerances[i].value_at(s.deviations.at(i)));
    for (const double v : s.metrics)
      out += "," + cell(v);
    std::string why = s.reason;
    std::replace(why.begin(), why.end(), '"', '\'');
    out += fmt::format(",\"{}\"\n", why);
  }
  return out;
}

std::vector<std::vector<double>> sensitivity_deviations(const ToleranceSet& set) {
  const std::size_t n = set.tolerances.size();
  std::vector<std::vector<double>> out{std::vector<double>(n, 0.0)};
  for (std::size_t i = 0; i < n; ++i) {
    for (const double d : {set.tolerances[i].distribution.min_deviation(),
                           set.tolerances[i].distribution.max_deviation()}) {
      std::vector<double> dev(n, 0.0);
      dev[i] = d;
      out.push_back(std::move(dev));
    }
  }
  return out;
}

std::vector<SensitivityRow> sensitivity_table(const ToleranceSet& set,
                                              const std::vector<SampleResult>& runs) {
  std::vector<SensitivityRow> rows;
  const SampleResult& nominal = runs.at(0);
  for (std::size_t i = 0; i < set.tolerances.size(); ++i) {
    SensitivityRow r;
    r.tolerance = i;
    r.lo = runs.at(1 + 2 * i);
    r.hi = runs.at(2 + 2 * i);
    for (const SampleResult* s : {&r.lo, &r.hi})
      for (std::size_t m = 0; m < metrics().size() && s->valid; ++m) {
        const double c = std::abs(change_pct(s->metrics[m], nominal.metrics[m]));
        if (std::isfinite(c))
          r.effect_pct = std::max(r.effect_pct, c);
      }
    // A plant that fails at a limit is the largest effect there is: it sorts first.
    if (!r.lo.valid || !r.hi.valid)
      r.effect_pct = kInf;
    rows.push_back(std::move(r));
  }
  std::stable_sort(rows.begin(), rows.end(), [](const SensitivityRow& a, const SensitivityRow& b) {
    return a.effect_pct > b.effect_pct;
  });
  return rows;
}

nlohmann::json sensitivity_json(const ToleranceSet& set, const SampleResult& nominal,
                                const std::vector<SensitivityRow>& rows) {
  nlohmann::json out{{"nominal", sample_json(set, nominal)}, {"rows", nlohmann::json::array()}};
  for (const SensitivityRow& r : rows) {
    nlohmann::json row{{"key", set.tolerances[r.tolerance].key},
                       {"effect_pct", number(r.effect_pct)},
                       {"source", set.tolerances[r.tolerance].source}};
    for (const auto& [side, s] : {std::pair{"lo", &r.lo}, std::pair{"hi", &r.hi}}) {
      nlohmann::json change = nlohmann::json::object();
      for (std::size_t m = 0; m < metrics().size(); ++m)
        change[metrics()[m].key] = number(change_pct(s->metrics[m], nominal.metrics[m]));
      row[side] = {{"deviation", s->deviations.at(r.tolerance)},
                   {"valid", s->valid},
                   {"reason", s->reason},
                   {"metrics", sample_json(set, *s).at("metrics")},
                   {"change_pct", change},
                   {"calibration_change", compensator_change(*s, nominal)}};
    }
    out["rows"].push_back(std::move(row));
  }
  return out;
}

}  // namespace piezoshift::tolerance
