// tolerance.md: what a reader needs to judge the tolerances, from the study's JSON.
#include <cmath>

#include <fmt/core.h>

#include "piezoshift/tolerance/tolerance_summary.hpp"

namespace piezoshift::tolerance {
namespace {

std::string value_text(const nlohmann::json& v) {
  if (v.is_null())
    return "–";
  if (v.is_string())
    return v.get<std::string>();
  return fmt::format("{:.4g}", v.get<double>());
}

std::string tolerances_table(const ToleranceSet& set) {
  std::string out = "| parameter | nominal | deviation | source |\n|---|---|---|---|\n";
  for (const Tolerance& t : set.tolerances)
    out += fmt::format("| `{}` | {:g} | {} | {} |\n", t.key, t.nominal, t.distribution.describe(),
                       t.source);
  return out;
}

std::string sensitivity_table_md(const nlohmann::json& sens) {
  std::string out =
      "## Sensitivity: each tolerance alone at its limits\n\n"
      "Change of each metric over the nominal plant, in %, at the tolerance's "
      "minimum / maximum deviation; sorted by the largest change. Travel, "
      "linearity and repeatability are after calibration (what the calibration "
      "absorbs does not show); the design's metrics are not calibrated.\n\n"
      "| parameter | largest |";
  for (const Metric& m : metrics())
    out += fmt::format(" {} |", m.key);
  out += "\n|---|---|";
  for (std::size_t i = 0; i < metrics().size(); ++i)
    out += "---|";
  out += "\n";
  std::string failures;
  for (const nlohmann::json& row : sens.at("rows")) {
    const nlohmann::json& effect = row.at("effect_pct");
    out += fmt::format("| `{}` | {} |", row.at("key").get<std::string>(),
                       effect.is_string() ? std::string("not valid")
                                          : fmt::format("{:.3g} %", effect.get<double>()));
    for (const char* side : {"lo", "hi"})
      if (!row.at(side).at("valid").get<bool>())
        failures += fmt::format("- `{}` at {} ({:g}): {}\n", row.at("key").get<std::string>(), side,
                                row.at(side).at("deviation").get<double>(),
                                row.at(side).at("reason").get<std::string>());
    for (const Metric& m : metrics())
      out += fmt::format(" {} / {} |", value_text(row.at("lo").at("change_pct").at(m.key)),
                         value_text(row.at("hi").at("change_pct").at(m.key)));
    out += "\n";
  }
  if (!failures.empty())
    out +=
        "\nNot valid at a limit (a plant that fails the spec whatever its bounds):\n\n" + failures;
  return out + "\n";
}

}  // namespace

std::string study_markdown(const ToleranceSet& set, const nlohmann::json& study,
                           const std::optional<nlohmann::json>& sensitivity,
                           const std::vector<std::string>& figures) {
  const nlohmann::json& h = study.at("study");
  const nlohmann::json& y = study.at("yield");
  std::string out = fmt::format(
      "# Tolerance study\n\n{} samples, seed {}, the {} calibration procedure, tolerances from "
      "`{}`.\n\n",
      h.at("samples").get<std::uint64_t>(), h.at("seed").get<std::uint64_t>(),
      h.at("procedure").get<std::string>(), set.source_name);
  out += "## Tolerances\n\n" + tolerances_table(set) + "\n";
  out += "## Yield\n\n";
  if (study.at("spec").empty()) {
    out += "No spec given: every valid sample passes.\n\n";
  } else {
    out += "Spec: ";
    for (const auto& [k, v] : study.at("spec").items())
      out += fmt::format("`{}` = {:g}; ", k, v.get<double>());
    out += "\n\n";
  }
  out += fmt::format(
      "{} of {} samples meet the spec ({:.1f} %); {} valid. A sample that is not valid counts as "
      "failing.\n\n",
      y.at("pass").get<std::size_t>(), y.at("samples").get<std::size_t>(),
      100.0 * y.at("fraction").get<double>(), y.at("valid").get<std::size_t>());
  if (sensitivity)
    out += sensitivity_table_md(*sensitivity);
  out +=
      "## Worst samples\n\nRerun one alone with `piezoshift tolerance ... --sample K`.\n\n"
      "| sample | margin | failure |\n|---|---|---|\n";
  for (const nlohmann::json& w : study.at("worst"))
    out += fmt::format("| {} | {} | {} |\n", w.at("index").get<std::uint64_t>(),
                       value_text(w.at("spec_margin")), w.at("spec_failure").get<std::string>());
  if (!figures.empty()) {
    out += "\n## Distributions\n\n";
    for (const std::string& f : figures)
      out += fmt::format("![{}]({}.svg)\n\n", f, f);
  }
  return out;
}

}  // namespace piezoshift::tolerance
