// The tolerance study's report: what a reader needs to judge the tolerances, from the study's JSON.
#include <cmath>

#include <fmt/core.h>

#include "piezoshift/tolerance/tolerance_summary.hpp"

namespace piezoshift::tolerance {
namespace {

using Rows = std::vector<std::vector<std::string>>;

std::string value_text(const nlohmann::json& v) {
  if (v.is_null())
    return "–";
  if (v.is_string())
    return v.get<std::string>();
  return fmt::format("{:.4g}", v.get<double>());
}

Rows tolerances_rows(const ToleranceSet& set) {
  Rows rows{{"parameter", "nominal", "deviation", "source"}};
  for (const Tolerance& t : set.tolerances)
    rows.push_back({t.key, fmt::format("{:g}", t.nominal), t.distribution.describe(), t.source});
  return rows;
}

// "ΔA 0.0123, p −1.2 %": what the calibration changed at one limit.
std::string absorbed_text(const nlohmann::json& side) {
  const nlohmann::json& c = side.at("calibration_change");
  if (c.at("A_max_abs_change").is_null())
    return "–";
  return fmt::format("ΔA {:.2g}, p {}{} %", c.at("A_max_abs_change").get<double>(),
                     c.at("p_6um_change_pct").get<double>() >= 0.0 ? "+" : "",
                     value_text(c.at("p_6um_change_pct")));
}

void sensitivity_section(reproduction::Document& doc, const nlohmann::json& sens) {
  doc.heading(2, "Sensitivity: each tolerance alone at its limits");
  doc.paragraph(
      "Change of each metric over the nominal plant, in %, at the tolerance's minimum / maximum "
      "deviation; sorted by the largest change. Travel, step, linearity and repeatability are "
      "measured after calibration; the design's metrics are not calibrated. \"Calibration "
      "absorbs\" is what the calibration changed to compensate, at the minimum / maximum: the "
      "largest change of an element of the transmission matrix A (Eq. 8) and the change of the "
      "polynomial's command for 6 µm, p(6 µm), in %.");
  std::vector<std::string> header{"parameter", "largest", "calibration absorbs"};
  for (const Metric& m : metrics())
    header.push_back(m.key);
  Rows rows{header};
  std::string failures;
  for (const nlohmann::json& row : sens.at("rows")) {
    const std::string key = row.at("key").get<std::string>();
    const nlohmann::json& effect = row.at("effect_pct");
    std::vector<std::string> r{key,
                               effect.is_string() ? std::string("not valid")
                                                  : fmt::format("{:.3g} %", effect.get<double>()),
                               absorbed_text(row.at("lo")) + " / " + absorbed_text(row.at("hi"))};
    for (const char* side : {"lo", "hi"})
      if (!row.at(side).at("valid").get<bool>())
        failures += fmt::format("{}{} at {} ({:g}): {}", failures.empty() ? "" : "; ", key, side,
                                row.at(side).at("deviation").get<double>(),
                                row.at(side).at("reason").get<std::string>());
    for (const Metric& m : metrics())
      r.push_back(value_text(row.at("lo").at("change_pct").at(m.key)) + " / " +
                  value_text(row.at("hi").at("change_pct").at(m.key)));
    rows.push_back(std::move(r));
  }
  doc.table(std::move(rows));
  if (!failures.empty())
    doc.paragraph("Not valid at a limit (a plant that fails the spec whatever its bounds): " +
                  failures + ".");
}

}  // namespace

std::vector<reproduction::Block> study_report(const ToleranceSet& set, const nlohmann::json& study,
                                              const std::optional<nlohmann::json>& sensitivity,
                                              const std::vector<ReportFigure>& figures) {
  const nlohmann::json& h = study.at("study");
  const nlohmann::json& y = study.at("yield");
  reproduction::Document doc;
  doc.heading(1, "Tolerance study");
  doc.paragraph(fmt::format(
      "{} samples, seed {}, the {} calibration procedure, the {} experiment set, tolerances from "
      "{}.",
      h.at("samples").get<std::uint64_t>(), h.at("seed").get<std::uint64_t>(),
      h.at("procedure").get<std::string>(), h.at("experiments").get<std::string>(),
      set.source_name));
  doc.heading(2, "Tolerances");
  doc.table(tolerances_rows(set));
  doc.heading(2, "Yield");
  if (study.at("spec").empty()) {
    doc.paragraph("No spec given: every valid sample passes.");
  } else {
    std::string spec = "Spec:";
    for (const auto& [k, v] : study.at("spec").items())
      spec += fmt::format(" {} = {:g};", k, v.get<double>());
    doc.paragraph(spec);
  }
  doc.paragraph(fmt::format(
      "{} of {} samples meet the spec ({:.1f} %); {} valid. A sample that is not valid counts as "
      "failing.",
      y.at("pass").get<std::size_t>(), y.at("samples").get<std::size_t>(),
      100.0 * y.at("fraction").get<double>(), y.at("valid").get<std::size_t>()));
  if (sensitivity)
    sensitivity_section(doc, *sensitivity);
  doc.heading(2, "Worst samples");
  doc.paragraph("Rerun one alone with piezoshift tolerance ... --sample K.");
  Rows worst{{"sample", "margin", "failure"}};
  for (const nlohmann::json& w : study.at("worst"))
    worst.push_back({std::to_string(w.at("index").get<std::uint64_t>()),
                     value_text(w.at("spec_margin")), w.at("spec_failure").get<std::string>()});
  doc.table(std::move(worst));
  if (!figures.empty()) {
    doc.heading(2, "Distributions");
    for (const ReportFigure& f : figures)
      doc.image(f.caption, f.path);
  }
  return doc.blocks;
}

}  // namespace piezoshift::tolerance
