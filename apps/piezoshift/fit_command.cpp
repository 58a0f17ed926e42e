// `piezoshift fit matrix|poly --data FILE.csv [--json]`: the feedforward calibration of the
// paper's Section 3 from recorded data (bench or twin), by least squares.
//   matrix  columns s1_um,s2_um,s3_um,z1_um,z2_um,z3_um, one row per pose:  S ~ A Z
//   poly    columns command_um,measured_um:  command ~ p3 m^3 + p2 m^2 + p1 m + p0
// Column order is free and other columns are ignored. Bad data (missing column, text or NaN in a
// cell, too few rows, a rank-deficient design, a missing file) exits with status 2 and a message
// naming the file and, where one applies, the line and column. Text for people, --json for
// programs. --out FILE writes the fitted A or p into a calibration file that `run` and `serve`
// load: an existing one keeps its other values (so `fit matrix` then `fit poly` into the same
// file gives both), a new one takes the paper's for them (docs/calibration.md).
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "piezoshift/calibration/calibration_file.hpp"
#include "piezoshift/calibration/matrix_fit.hpp"
#include "piezoshift/calibration/poly_fit.hpp"
#include "piezoshift/io/csv_table.hpp"

namespace piezoshift::app {
namespace {

using Json = nlohmann::ordered_json;

struct FitOptions {
  std::string data_path;
  bool json = false;
  std::string out;  //!< calibration file to write, empty: none
};

// Replaces A or p (set) in the calibration file o.out, keeping everything else it holds.
template <class Set>
void write_into_calibration(const FitOptions& o, const char* what, Set&& set) {
  control::SemiClosedLoopParams params;
  std::optional<double> z_max, z_min;
  std::error_code ec;
  const bool existing = std::filesystem::exists(o.out, ec);
  if (existing)
    params = calibration::load_calibration_file(o.out, &z_max, &z_min);
  set(params);
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
    throw io::InputError(fmt::format("{}: {}", path, e.what()));
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
    write_into_calibration(o, "A", [&](control::SemiClosedLoopParams& p) { p.matrix = r.a; });
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
    write_into_calibration(o, "p", [&](control::SemiClosedLoopParams& p) { p.polynomial = r.p; });
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

}  // namespace

void add_fit_command(CLI::App& app, Action& action) {
  CLI::App* fit =
      app.add_subcommand("fit", "Least-squares calibration of A and p from recorded data");
  fit->require_subcommand(1);
  auto options = std::make_shared<FitOptions>();

  CLI::App* matrix = fit->add_subcommand(
      "matrix", "Transmission matrix S ~ A Z (columns s1_um..s3_um, z1_um..z3_um)");
  CLI::App* poly = fit->add_subcommand(
      "poly", "Cubic linearization command ~ p(measured) (columns command_um, measured_um)");
  for (CLI::App* sub : {matrix, poly}) {
    sub->add_option("--data", options->data_path, "CSV file with a header row")->required();
    sub->add_flag("--json", options->json, "Machine-readable output");
    sub->add_option("--out", options->out,
                    "calibration file to write the fit into (TOML; an existing one keeps its "
                    "other values)");
  }
  matrix->callback([&action, options] { action = [options] { return run_matrix(*options); }; });
  poly->callback([&action, options] { action = [options] { return run_poly(*options); }; });
}

}  // namespace piezoshift::app
