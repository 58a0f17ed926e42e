// `piezoshift fit matrix|poly|improved --data FILE.csv [--json]`: the feedforward calibration of
// the paper's Section 3, and the improved controller's models, from recorded data (bench or
// twin), by least squares.
//   matrix    columns s1_um,s2_um,s3_um,z1_um,z2_um,z3_um, one row per pose:  S ~ A Z
//   poly      columns command_um,measured_um:  command ~ p3 m^3 + p2 m^2 + p1 m + p0
//   improved  columns t_s,u1_um..u3_um,sgs1_um..sgs3_um, one row per tick of an open-loop
//             excitation (the channel models); --mode-data t_s,measured_um, the interferometer
//             after a small step (the plate's mode); the loop's rate is the excitation's
// Column order is free and other columns are ignored. Bad data (missing column, text or NaN in a
// cell, too few rows, a rank-deficient design, a missing file) exits with status 2 and a message
// naming the file and, where one applies, the line and column. Text for people, --json for
// programs. --out FILE writes the fitted A or p into a calibration file that `run` and `serve`
// load: an existing one keeps its other values (so `fit matrix` then `fit poly` into the same
// file gives both), a new one takes the paper's for them (docs/calibration.md).
#include <array>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "improved_summary.hpp"
#include "piezoshift/calibration/calibration_file.hpp"
#include "piezoshift/calibration/matrix_fit.hpp"
#include "piezoshift/calibration/poly_fit.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/csv_table.hpp"
#include "piezoshift/runtime/safety_ranges.hpp"

namespace piezoshift::app {
namespace {

using Json = nlohmann::ordered_json;

struct FitOptions {
  std::string data_path;
  bool json = false;
  std::string out;        //!< calibration file to write, empty: none
  std::string mode_path;  //!< improved: the ring-down, empty: none
  std::string config;     //!< improved: the installation (the amplifier's slew)
};

// Replaces A or p, or the improved controller (set) in the calibration file o.out, keeping
// everything else it holds.
template <class Set>
void write_into_calibration(const FitOptions& o, const char* what, Set&& set) {
  control::SemiClosedLoopParams params;
  std::optional<double> z_max, z_min;
  std::error_code ec;
  const bool existing = std::filesystem::exists(o.out, ec);
  if (existing)
    params = calibration::load_calibration_file(o.out, &z_max, &z_min);
  params = set(params);
  work_begins();  // the file
  calibration::write_calibration_file(
      o.out, params,
      fmt::format("piezoshift calibration: {} fitted by `piezoshift fit` from {}\n{}", what,
                  o.data_path,
                  existing ? "the other values kept from the file this replaced"
                           : "the other values the paper's (Section 4)"),
      z_max, z_min);
}

// Runs a fit; a FitError (which does not know the file) gets the file name in front.
template <class F>
auto with_file(const std::string& path, F&& fit) {
  try {
    return fit();
  } catch (const calibration::FitError& e) {
    throw core::InputError(fmt::format("{}: {}", path, e.what()));
  }
}

int run_matrix(const FitOptions& o) {
  const io::CsvTable t = io::CsvTable::load(o.data_path);
  t.require_columns({"s1_um", "s2_um", "s3_um", "z1_um", "z2_um", "z3_um"});
  const char* s_names[] = {"s1_um", "s2_um", "s3_um"};
  const char* z_names[] = {"z1_um", "z2_um", "z3_um"};
  std::vector<control::Vec3> s(t.rows()), z(t.rows());
  for (std::size_t j = 0; j < 3; ++j) {
    const std::vector<double> sj = t.column(s_names[j]);
    const std::vector<double> zj = t.column(z_names[j]);
    for (std::size_t i = 0; i < t.rows(); ++i) {
      s[i][j] = sj[i];
      z[i][j] = zj[i];
    }
  }
  const calibration::MatrixFitResult r =
      with_file(o.data_path, [&] { return calibration::fit_transmission_matrix(s, z); });
  const auto& a = r.a.a;
  if (!o.out.empty())
    write_into_calibration(o, "A", [&](control::SemiClosedLoopParams p) {
      p.matrix = r.a;
      return p;
    });
  if (o.json) {
    Json rows = Json::array();
    for (const auto& row : a)
      rows.push_back(Json{row[0], row[1], row[2]});
    Json out{{"data", o.data_path},
             {"poses", r.poses},
             {"A", rows},
             {"rms_residual_um", r.rms_residual_um},
             {"rms_residual_per_s_um", r.rms_residual_per_s_um},
             {"condition_number", r.condition_number},
             {"design_condition_number", r.design_condition_number}};
    if (!o.out.empty())
      out["calibration_file"] = o.out;
    fmt::print("{}\n", out.dump(2));
    return 0;
  }
  fmt::print("Transmission matrix S = A Z from {} poses in {}\n", r.poses, o.data_path);
  for (const auto& row : a)
    fmt::print("  [{:10.6f} {:10.6f} {:10.6f}]\n", row[0], row[1], row[2]);
  fmt::print("rms residual              {:.6f} um (S1 {:.6f}, S2 {:.6f}, S3 {:.6f})\n",
             r.rms_residual_um, r.rms_residual_per_s_um[0], r.rms_residual_per_s_um[1],
             r.rms_residual_per_s_um[2]);
  fmt::print("condition number of A     {:.4g}\n", r.condition_number);
  fmt::print("condition number of Z     {:.4g}\n", r.design_condition_number);
  if (r.poses == calibration::kMatrixFitMinPoses)
    fmt::print("note: 3 poses determine A exactly; the residual is 0 by construction\n");
  if (!o.out.empty())
    fmt::print("written: {} (A)\n", o.out);
  return 0;
}

int run_poly(const FitOptions& o) {
  const io::CsvTable t = io::CsvTable::load(o.data_path);
  t.require_columns({"command_um", "measured_um"});
  const std::vector<double> c = t.column("command_um");
  const std::vector<double> m = t.column("measured_um");
  const calibration::PolyFitResult r =
      with_file(o.data_path, [&] { return calibration::fit_cubic_polynomial(m, c); });
  if (!o.out.empty())
    write_into_calibration(o, "p", [&](control::SemiClosedLoopParams p) {
      p.polynomial = r.p;
      return p;
    });
  if (o.json) {
    Json out{{"data", o.data_path},
             {"points", r.points},
             {"p", {r.p.p3, r.p.p2, r.p.p1, r.p.p0}},
             {"rms_residual_um", r.rms_residual_um},
             {"max_abs_residual_um", r.max_abs_residual_um},
             {"condition_number", r.condition_number},
             {"condition_number_unscaled", r.condition_number_unscaled}};
    if (!o.out.empty())
      out["calibration_file"] = o.out;
    fmt::print("{}\n", out.dump(2));
    return 0;
  }
  fmt::print("Cubic linearization command = p(measured) from {} points in {}\n", r.points,
             o.data_path);
  fmt::print("  p3 = {:.7g} 1/um^2\n  p2 = {:.7g} 1/um\n  p1 = {:.7g}\n  p0 = {:.7g} um\n", r.p.p3,
             r.p.p2, r.p.p1, r.p.p0);
  fmt::print("rms residual              {:.6f} um (max {:.6f} um)\n", r.rms_residual_um,
             r.max_abs_residual_um);
  fmt::print("condition number          {:.4g} (centred and scaled design; raw {:.4g})\n",
             r.condition_number, r.condition_number_unscaled);
  if (!o.out.empty())
    fmt::print("written: {} (p)\n", o.out);
  return 0;
}

// The step of t_s in a record that must hold one row per sample, evenly spaced (a gap, a repeat
// or a jitter over 1 % of the step is an error naming the row), as a rate rounded to a whole
// hertz when it is within 0.1 % of one (a bench clock's drift must not make the file's rate
// differ from the loop's, which `run` checks to 1e-9).
double record_step_s(const io::CsvTable& t, const std::vector<double>& ts) {
  if (ts.size() < 2)
    throw core::InputError(
        fmt::format("{}: {} data rows; a record needs many", t.source(), ts.size()));
  const double mean = (ts.back() - ts.front()) / static_cast<double>(ts.size() - 1);
  if (!(mean > 0.0))
    throw core::InputError(fmt::format("{}: t_s does not increase", t.source()));
  for (std::size_t k = 1; k < ts.size(); ++k) {
    const double dt = ts[k] - ts[k - 1];
    if (std::fabs(dt - mean) > 0.01 * mean)
      throw core::InputError(fmt::format(
          "{}:{}: t_s steps by {:.6g} s where the record's mean step is {:.6g} s: the fit needs "
          "one row per sample, evenly spaced",
          t.source(), t.line_of_row(k), dt, mean));
  }
  const double rate_Hz = std::round(1.0 / mean);
  return std::fabs(rate_Hz * mean - 1.0) < 1e-3 ? 1.0 / rate_Hz : mean;
}

int run_improved(const FitOptions& o) {
  const config::ProjectConfig config = o.config.empty()
                                           ? config::ProjectConfig{}
                                           : runtime::load_installation_config(o.config).project;
  const io::CsvTable t = load_record(o.data_path);
  t.require_columns({"t_s", "u1_um", "u2_um", "u3_um", "sgs1_um", "sgs2_um", "sgs3_um"});
  const double sample_time_s = record_step_s(t, t.column("t_s"));
  work_begins();  // the three hysteresis and creep fits, the controller's design
  std::array<calibration::HysteresisFit, 3> model;
  for (std::size_t i = 0; i < 3; ++i) {
    const std::vector<double> u = t.column(fmt::format("u{}_um", i + 1));
    const std::vector<double> y = t.column(fmt::format("sgs{}_um", i + 1));
    model[i] = with_file(o.data_path,
                         [&] { return calibration::fit_hysteresis_creep(u, y, sample_time_s); });
  }
  calibration::PlateModeEstimate mode;
  if (!o.mode_path.empty()) {
    const io::CsvTable m = load_record(o.mode_path);
    m.require_columns({"t_s", "measured_um"});
    const double step_s = record_step_s(m, m.column("t_s"));
    mode = calibration::identify_plate_mode(m.column("measured_um"), 1.0 / step_s);
  }
  bool shaped = false;
  const auto design = [&](control::SemiClosedLoopParams base) {
    base.sample_time_s = sample_time_s;
    const calibration::ImprovedDesign d =
        calibration::design_improved_controller(config, base, model, mode);
    shaped = d.shaped;
    return d.controller;
  };
  control::SemiClosedLoopParams params;
  if (o.out.empty())
    params = design(params);
  else
    write_into_calibration(o, "the improved controller",
                           [&](control::SemiClosedLoopParams p) { return params = design(p); });
  const ImprovedSummary summary{params.improved, model, mode, shaped};
  if (o.json) {
    Json out{{"data", o.data_path}, {"mode_data", o.mode_path}};
    out.update(improved_json(summary));
    if (!o.out.empty())
      out["calibration_file"] = o.out;
    fmt::print("{}\n", out.dump(2));
    return 0;
  }
  fmt::print("Improved controller's models from {} ({} rows at {:g} Hz){}\n", o.data_path, t.rows(),
             1.0 / sample_time_s,
             o.mode_path.empty() ? "" : fmt::format(" and the ring-down in {}", o.mode_path));
  print_improved(summary);
  if (!o.out.empty())
    fmt::print("written: {} (the improved controller; A and p kept)\n", o.out);
  return 0;
}

}  // namespace

void add_fit_command(CLI::App& app, Action& action) {
  CLI::App* fit = app.add_subcommand(
      "fit",
      "Least-squares calibration of A and p, or of the improved controller, from recorded data");
  fit->require_subcommand(1);
  auto options = std::make_shared<FitOptions>();

  CLI::App* matrix = fit->add_subcommand(
      "matrix", "Transmission matrix S ~ A Z (columns s1_um..s3_um, z1_um..z3_um)");
  CLI::App* poly = fit->add_subcommand(
      "poly", "Cubic linearization command ~ p(measured) (columns command_um, measured_um)");
  CLI::App* improved = fit->add_subcommand(
      "improved",
      "The improved controller's channel models from an open-loop excitation (columns t_s, "
      "u1_um..u3_um, sgs1_um..sgs3_um), its shaper from a ring-down (--mode-data)");
  improved->add_option("--mode-data", options->mode_path,
                       "the interferometer after a small step (columns t_s, measured_um)");
  improved->add_option("--config", options->config,
                       "installation file (TOML) with the amplifier that sets the rate limit");
  for (CLI::App* sub : {matrix, poly, improved}) {
    sub->add_option("--data", options->data_path, "CSV file with a header row")->required();
    sub->add_flag("--json", options->json, "Machine-readable output");
    sub->add_option("--out", options->out,
                    "calibration file to write the fit into (TOML; an existing one keeps its "
                    "other values)");
  }
  matrix->callback([&action, options] { action = [options] { return run_matrix(*options); }; });
  poly->callback([&action, options] { action = [options] { return run_poly(*options); }; });
  improved->callback([&action, options] { action = [options] { return run_improved(*options); }; });
}

}  // namespace piezoshift::app
