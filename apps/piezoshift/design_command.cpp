// `piezoshift design`: the flexure design report (paper, Section 2.2), or with --search a grid
// search over the hinge dimensions. Text for people, --json for programs (units in every key).
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/design/design_evaluation.hpp"
#include "piezoshift/design/hinge_search.hpp"
#include "piezoshift/runtime/safety_ranges.hpp"

namespace piezoshift::app {

namespace {

using Json = nlohmann::ordered_json;

struct DesignOptions {
  std::string config_path;  // empty: the paper's values (the structs' defaults)
  bool json = false;
  bool search = false;
  // Search ranges as MIN MAX STEP in millimetres; empty keeps the default grid.
  std::vector<double> thickness_mm, radius_mm, width_mm, length_mm;
  std::int64_t top = 10;
  double max_stiffness_ratio = design::SearchConstraints{}.max_stiffness_ratio;
  double min_stress_margin = design::SearchConstraints{}.min_stress_margin;
  double max_t_over_r = design::SearchConstraints{}.max_thickness_to_radius;
  double min_frequency_Hz = design::SearchConstraints{}.min_natural_frequency_Hz;
  std::string rank_by = "frequency";
};

Json inputs_json(const design::DesignInputs& in) {
  const auto& a = in.actuator;
  const auto& m = in.material;
  const auto& h = in.hinge;
  return Json{{"actuator",
               {{"stiffness_N_per_um", a.stiffness_N_per_um},
                {"nominal_stroke_um", a.nominal_stroke_um},
                {"pushing_force_N", a.pushing_force_N},
                {"pulling_force_N", a.pulling_force_N},
                {"capacitance_F", a.capacitance_F},
                {"resonance_frequency_Hz", a.resonance_frequency_Hz},
                {"length_m", a.length_m}}},
              {"material",
               {{"elastic_modulus_Pa", m.elastic_modulus_Pa},
                {"poisson_ratio", m.poisson_ratio},
                {"density_kg_per_m3", m.density_kg_per_m3},
                {"allowable_stress_Pa", m.allowable_stress_Pa}}},
              {"hinge",
               {{"width_m", h.width_m},
                {"thickness_m", h.thickness_m},
                {"radius_m", h.radius_m},
                {"link_length_m", h.link_length_m}}},
              {"mechanism", {{"moving_mass_kg", in.mechanism.moving_mass_kg}}}};
}

Json evaluation_json(const design::DesignEvaluation& e) {
  return Json{{"angular_stiffness_Nm_per_rad", e.hinge_angular_stiffness_Nm_per_rad},
              {"mechanism_stiffness_N_per_um", e.mechanism_stiffness_N_per_um},
              {"stiffness_rule_limit_N_per_um", e.stiffness_rule_limit_N_per_um},
              {"stiffness_ratio", e.stiffness_ratio},
              {"rule_ka_over_10_ok", e.rule_ka_over_10_ok},
              {"available_displacement_um", e.available_displacement_um},
              {"stroke_loss_percent", e.stroke_loss_percent},
              {"spring_force_at_stroke_N", e.spring_force_at_stroke_N},
              {"force_within_pushing_limit", e.force_within_pushing_limit},
              {"hinge_rotation_at_stroke_rad", e.hinge_rotation_at_stroke_rad},
              {"hinge_moment_at_stroke_Nm", e.hinge_moment_at_stroke_Nm},
              {"stress_concentration_factor", e.stress_concentration_factor},
              {"nominal_stress_at_stroke_Pa", e.nominal_stress_at_stroke_Pa},
              {"max_stress_at_stroke_Pa", e.max_stress_at_stroke_Pa},
              {"allowable_stress_Pa", e.allowable_stress_Pa},
              {"stress_margin", e.stress_margin},
              {"stress_ok", e.stress_ok},
              {"natural_frequency_Hz", e.natural_frequency_Hz},
              {"thickness_to_radius", e.thickness_to_radius}};
}

const char* ok(bool good) {
  return good ? "ok" : "NOT MET";
}

void print_report(const design::DesignInputs& in, const design::DesignEvaluation& e,
                  const std::string& source) {
  // The paper's own numbers are shown beside ours only when the inputs are the paper's.
  const bool paper = in == design::DesignInputs{};
  auto cite = [paper](const char* text) { return paper ? fmt::format("  ({})", text) : ""; };
  const auto& a = in.actuator;
  const auto& m = in.material;
  const auto& h = in.hinge;

  fmt::print("Flexure design: double parallel four-bar mechanism, 8 right-circular hinges\n");
  fmt::print("configuration: {}\n\n", source);
  fmt::print("Inputs\n");
  fmt::print("  actuator   k_a = {:g} N/um, free stroke x_a = {:g} um, pushing force {:g} N\n",
             a.stiffness_N_per_um, a.nominal_stroke_um, a.pushing_force_N);
  fmt::print("  material   E = {:g} GPa, nu = {:g}, rho = {:g} kg/m^3, allowable {:g} MPa\n",
             m.elastic_modulus_Pa * 1e-9, m.poisson_ratio, m.density_kg_per_m3,
             m.allowable_stress_Pa * 1e-6);
  fmt::print("  hinge      b = {:g} mm, t = {:g} mm, R = {:g} mm, L = {:g} mm (t/R = {:.3f})\n",
             h.width_m * 1e3, h.thickness_m * 1e3, h.radius_m * 1e3, h.link_length_m * 1e3,
             e.thickness_to_radius);
  fmt::print("  mechanism  moving mass m = {:g} kg\n\n", in.mechanism.moving_mass_kg);

  fmt::print("Stiffness\n");
  fmt::print("  hinge angular stiffness k_alpha_z   {:10.2f} N m/rad   Eq. 2\n",
             e.hinge_angular_stiffness_Nm_per_rad);
  fmt::print("  mechanism stiffness     k_m         {:10.3f} N/um      Eq. 3{}\n",
             e.mechanism_stiffness_N_per_um, cite("paper: 6.78 N/um"));
  fmt::print("  rule k_m < k_a/10       k_a/10      {:10.3f} N/um      k_m/k_a = {:.4f}: {}\n\n",
             e.stiffness_rule_limit_N_per_um, e.stiffness_ratio, ok(e.rule_ka_over_10_ok));

  fmt::print("Stroke\n");
  fmt::print("  available displacement x_m         {:10.3f} um        Eq. 1{}\n",
             e.available_displacement_um, cite("paper: 14.6 um"));
  fmt::print("  stroke loss             1 - x_m/x_a {:10.2f} %\n", e.stroke_loss_percent);
  fmt::print("  spring force at x_m     k_m x_m     {:10.2f} N         <= {:g} N pushing: {}\n\n",
             e.spring_force_at_stroke_N, a.pushing_force_N, ok(e.force_within_pushing_limit));

  fmt::print("Hinge stress at x_m (K_t of Yong, Lu & Handley 2008)\n");
  fmt::print("  hinge rotation          x_m/L       {:10.4f} mrad\n",
             e.hinge_rotation_at_stroke_rad * 1e3);
  fmt::print("  bending moment          M           {:10.4f} N m\n", e.hinge_moment_at_stroke_Nm);
  fmt::print("  nominal stress          6M/(b t^2)  {:10.2f} MPa\n",
             e.nominal_stress_at_stroke_Pa * 1e-6);
  fmt::print("  stress concentration    K_t         {:10.4f}\n", e.stress_concentration_factor);
  fmt::print("  maximum stress          sigma_max   {:10.2f} MPa{}\n",
             e.max_stress_at_stroke_Pa * 1e-6, cite("paper's FEA: 47.63 MPa"));
  fmt::print(
      "  margin                  allow/max   {:10.2f}           (allowable {:g} MPa): {}\n\n",
      e.stress_margin, e.allowable_stress_Pa * 1e-6, ok(e.stress_ok));

  fmt::print("Dynamics\n");
  fmt::print("  first natural frequency f           {:10.1f} Hz        sqrt(k_m/m)/(2 pi){}\n",
             e.natural_frequency_Hz, cite("paper's FEA: 1839 Hz, which sets m"));
}

// Checks one MIN MAX STEP option (in mm) and turns it into a range in metres.
design::SearchRange range_option(const char* option, const std::vector<double>& mm,
                                 const design::SearchRange& fallback) {
  if (mm.empty())
    return fallback;
  auto bad = [option, &mm](const std::string& why) {
    return core::InputError(
        fmt::format("option {} {} {} {}: {}", option, mm[0], mm[1], mm[2], why));
  };
  for (const double v : mm) {
    if (!std::isfinite(v))
      throw bad("every value must be a finite number");
  }
  if (!(mm[0] > 0.0))
    throw bad("MIN must be > 0");
  if (!(mm[1] >= mm[0]))
    throw bad("MAX must be >= MIN");
  if (!(mm[2] > 0.0))
    throw bad("STEP must be > 0");
  // Divide (not multiply by 1e-3) so that e.g. 18 mm is exactly the double nearest 0.018 m.
  const design::SearchRange range{mm[0] / 1000.0, mm[1] / 1000.0, mm[2] / 1000.0};
  if (!design::search_range_problem(range).empty())
    throw bad(
        fmt::format("more than {} values; use a larger STEP", design::max_search_grid_points));
  return range;
}

double positive_option(const char* option, double value) {
  if (!(std::isfinite(value) && value > 0.0))
    throw core::InputError(fmt::format("option {} {}: must be a positive number", option, value));
  return value;
}

Json range_json(const design::SearchRange& r) {
  return Json{{"min_m", r.min_m}, {"max_m", r.max_m}, {"step_m", r.step_m}};
}

int run_search(const DesignOptions& opt, const design::DesignInputs& in,
               const std::string& source) {
  const design::HingeSearchSpace defaults;
  design::HingeSearchSpace space;
  space.thickness = range_option("--thickness-mm", opt.thickness_mm, defaults.thickness);
  space.radius = range_option("--radius-mm", opt.radius_mm, defaults.radius);
  space.width = range_option("--width-mm", opt.width_mm, defaults.width);
  space.link_length = range_option("--length-mm", opt.length_mm, defaults.link_length);
  const double points = static_cast<double>(design::search_range_size(space.thickness)) *
                        static_cast<double>(design::search_range_size(space.radius)) *
                        static_cast<double>(design::search_range_size(space.width)) *
                        static_cast<double>(design::search_range_size(space.link_length));
  if (points > static_cast<double>(design::max_search_evaluations)) {
    throw core::InputError(
        fmt::format("--search: the grid has {:g} points, more than {}; use larger "
                    "steps or narrower ranges",
                    points, design::max_search_evaluations));
  }
  work_begins();  // the grid
  design::SearchConstraints c;
  c.max_stiffness_ratio = positive_option("--max-stiffness-ratio", opt.max_stiffness_ratio);
  c.min_stress_margin = positive_option("--min-stress-margin", opt.min_stress_margin);
  c.max_thickness_to_radius = positive_option("--max-t-over-r", opt.max_t_over_r);
  if (!(std::isfinite(opt.min_frequency_Hz) && opt.min_frequency_Hz >= 0.0)) {
    throw core::InputError(
        fmt::format("option --min-frequency-hz {}: must be a number >= 0", opt.min_frequency_Hz));
  }
  c.min_natural_frequency_Hz = opt.min_frequency_Hz;
  const auto ranking = opt.rank_by == "margin" ? design::SearchRanking::stress_margin
                                               : design::SearchRanking::natural_frequency;
  const char* rank_text = ranking == design::SearchRanking::stress_margin
                              ? "stress margin, then natural frequency"
                              : "natural frequency, then stress margin";

  const design::HingeSearchResult result =
      design::search_hinge_designs(in, space, c, static_cast<std::size_t>(opt.top), ranking);

  if (opt.json) {
    Json candidates = Json::array();
    for (const auto& cand : result.candidates) {
      Json j{{"width_m", cand.hinge.width_m},
             {"thickness_m", cand.hinge.thickness_m},
             {"radius_m", cand.hinge.radius_m},
             {"link_length_m", cand.hinge.link_length_m}};
      j.update(evaluation_json(cand.evaluation));
      candidates.push_back(std::move(j));
    }
    const Json out{{"config_file", opt.config_path.empty() ? Json(nullptr) : Json(opt.config_path)},
                   {"search_space",
                    {{"thickness", range_json(space.thickness)},
                     {"radius", range_json(space.radius)},
                     {"width", range_json(space.width)},
                     {"link_length", range_json(space.link_length)}}},
                   {"constraints",
                    {{"max_stiffness_ratio", c.max_stiffness_ratio},
                     {"min_stress_margin", c.min_stress_margin},
                     {"max_thickness_to_radius", c.max_thickness_to_radius},
                     {"min_natural_frequency_Hz", c.min_natural_frequency_Hz}}},
                   {"rank_by", opt.rank_by},
                   {"evaluated_count", result.evaluated_count},
                   {"geometry_rejected_count", result.geometry_rejected_count},
                   {"feasible_count", result.feasible_count},
                   {"candidates", std::move(candidates)}};
    fmt::print("{}\n", out.dump(2));
    return 0;
  }

  fmt::print("Hinge search (actuator, material and moving mass from: {})\n", source);
  auto mm = [](const design::SearchRange& r) {
    return fmt::format("{:g}..{:g} by {:g} mm", r.min_m * 1e3, r.max_m * 1e3, r.step_m * 1e3);
  };
  fmt::print("  grid        t {}, R {}, b {}, L {}\n", mm(space.thickness), mm(space.radius),
             mm(space.width), mm(space.link_length));
  fmt::print("  geometry    t < 2R, L > 2R, t/R <= {:g}\n", c.max_thickness_to_radius);
  fmt::print(
      "  feasible    k_m/k_a <= {:g}, allowable/sigma_max(x_m) >= {:g}, k_m x_m <= {:g} N, "
      "f >= {:g} Hz\n",
      c.max_stiffness_ratio, c.min_stress_margin, in.actuator.pushing_force_N,
      c.min_natural_frequency_Hz);
  fmt::print("  {} geometries, {} rejected by geometry, {} feasible; best {} by {}:\n\n",
             result.evaluated_count, result.geometry_rejected_count, result.feasible_count,
             result.candidates.size(), rank_text);
  if (result.candidates.empty()) {
    fmt::print("  no feasible design in this grid\n");
    return 0;
  }
  fmt::print("  {:>4} {:>6} {:>6} {:>6} {:>6} {:>10} {:>8} {:>8} {:>10} {:>7} {:>8}\n", "rank",
             "t[mm]", "R[mm]", "b[mm]", "L[mm]", "k_m[N/um]", "k_m/k_a", "x_m[um]", "sigma[MPa]",
             "margin", "f[Hz]");
  int rank = 1;
  for (const auto& cand : result.candidates) {
    const auto& h = cand.hinge;
    const auto& e = cand.evaluation;
    fmt::print(
        "  {:>4} {:>6.2f} {:>6.2f} {:>6.2f} {:>6.2f} {:>10.3f} {:>8.4f} {:>8.3f} {:>10.2f} "
        "{:>7.2f} {:>8.1f}\n",
        rank++, h.thickness_m * 1e3, h.radius_m * 1e3, h.width_m * 1e3, h.link_length_m * 1e3,
        e.mechanism_stiffness_N_per_um, e.stiffness_ratio, e.available_displacement_um,
        e.max_stress_at_stroke_Pa * 1e-6, e.stress_margin, e.natural_frequency_Hz);
  }
  return 0;
}

int run_design(const DesignOptions& opt) {
  design::DesignInputs inputs;
  std::string source = "the paper's values (Tables 1 to 3; no --config)";
  if (!opt.config_path.empty()) {
    inputs = runtime::load_installation_config(opt.config_path).project.design;
    source = opt.config_path;
  }
  if (opt.search)
    return run_search(opt, inputs, source);

  const design::DesignEvaluation e = design::evaluate_design(inputs);
  if (opt.json) {
    Json out{{"config_file", opt.config_path.empty() ? Json(nullptr) : Json(opt.config_path)}};
    out.update(evaluation_json(e));
    out["inputs"] = inputs_json(inputs);
    fmt::print("{}\n", out.dump(2));
  } else {
    print_report(inputs, e, source);
  }
  return 0;
}

}  // namespace

void add_design_command(CLI::App& app, Action& action) {
  CLI::App* cmd = app.add_subcommand(
      "design", "Flexure design report (paper, Section 2.2), or a search over hinge dimensions");
  auto opt = std::make_shared<DesignOptions>();
  cmd->add_option("--config", opt->config_path,
                  "TOML file with [actuator], [material], [hinge], [mechanism] "
                  "(absent keys keep the paper's values)");
  cmd->add_flag("--json", opt->json, "print one JSON object instead of the text report");
  CLI::Option* search =
      cmd->add_flag("--search", opt->search,
                    "search hinge dimensions for designs meeting the stiffness and stress limits");
  auto range = [&](const char* name, std::vector<double>& target, const char* what,
                   const design::SearchRange& d) {
    cmd->add_option(name, target,
                    fmt::format("{} grid MIN MAX STEP in mm (default {:g} {:g} {:g})", what,
                                d.min_m * 1e3, d.max_m * 1e3, d.step_m * 1e3))
        ->expected(3)
        ->delimiter(',')
        ->needs(search);
  };
  const design::HingeSearchSpace d;
  range("--thickness-mm", opt->thickness_mm, "hinge thickness t", d.thickness);
  range("--radius-mm", opt->radius_mm, "notch radius R", d.radius);
  range("--width-mm", opt->width_mm, "hinge width b", d.width);
  range("--length-mm", opt->length_mm, "link length L", d.link_length);
  cmd->add_option("--top", opt->top, "number of ranked candidates to show (default 10)")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{100000}))
      ->needs(search);
  cmd->add_option("--max-stiffness-ratio", opt->max_stiffness_ratio,
                  "feasible when k_m/k_a <= this (default 0.1)")
      ->needs(search);
  cmd->add_option("--min-stress-margin", opt->min_stress_margin,
                  "feasible when allowable/max stress at x_m >= this (default 2)")
      ->needs(search);
  cmd->add_option("--max-t-over-r", opt->max_t_over_r,
                  "geometry limit on t/R, where Eq. 2 is meant to hold (default 1)")
      ->needs(search);
  cmd->add_option("--min-frequency-hz", opt->min_frequency_Hz,
                  "feasible when the natural frequency >= this (default 0: no limit)")
      ->needs(search);
  cmd->add_option("--rank-by", opt->rank_by,
                  "rank feasible designs by 'frequency' (stiffest first) or 'margin' (strongest "
                  "first); default frequency")
      ->check(CLI::IsMember({"frequency", "margin"}))
      ->needs(search);
  cmd->callback([&action, opt] { action = [opt] { return run_design(*opt); }; });
}

}  // namespace piezoshift::app
