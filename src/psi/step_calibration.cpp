#include "piezoshift/psi/step_calibration.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include <fmt/core.h>
#include <Eigen/Dense>

namespace piezoshift::psi {
namespace {

std::string toml_array(const std::vector<double>& v) {
  std::string s = "[";
  for (std::size_t k = 0; k < v.size(); ++k)
    s += fmt::format("{}{:.9g}", k ? ", " : "", v[k]);
  return s + "]";
}

}  // namespace

StepCalibration calibrate_steps(std::span<const double> steps, double s, double wavelength_nm) {
  const auto n = static_cast<Eigen::Index>(steps.size());
  if (n < 3 || !(s >= kMinNominalStepRad && s <= kMaxNominalStepRad))
    throw std::invalid_argument(
        fmt::format("step calibration: at least 3 steps and a nominal step in [{:g}, {:.4f}] rad",
                    kMinNominalStepRad, kMaxNominalStepRad));
  StepCalibration c;
  c.wavelength_nm = wavelength_nm;
  c.nominal_step_rad = s;
  c.steps_rad.assign(steps.begin(), steps.end());
  const double nm_per_rad = wavelength_nm / (4.0 * std::numbers::pi);
  Eigen::MatrixXd X(n, 2);
  Eigen::VectorXd y(n);
  double line_num = 0.0, line_den = 0.0, sq = 0.0;
  for (Eigen::Index k = 0; k < n; ++k) {
    const double nominal = s * static_cast<double>(k);
    const double d = steps[static_cast<std::size_t>(k)];
    X.row(k) << nominal, nominal * nominal;
    y(k) = d;
    line_num += nominal * d;
    line_den += nominal * nominal;
    sq += (d - nominal) * (d - nominal);
    c.steps_nm.push_back(d * nm_per_rad);
    if (k > 0)
      c.increments_nm.push_back((d - steps[static_cast<std::size_t>(k - 1)]) * nm_per_rad);
  }
  const Eigen::Vector2d gq = X.colPivHouseholderQr().solve(y);
  c.quadratic_per_rad = gq(1);
  c.step_gain = line_num / line_den;  // best line through the origin
  double worst = 0.0;
  for (Eigen::Index k = 0; k < n; ++k)
    worst = std::max(worst, std::fabs(y(k) - c.step_gain * s * static_cast<double>(k)));
  const double span = std::fabs(y(n - 1));
  c.nonlinearity_pct = span > 0.0 ? 100.0 * worst / span : 0.0;
  c.rms_step_error_rad = std::sqrt(sq / static_cast<double>(n));
  return c;
}

std::string step_calibration_problem(const StepCalibration& c) {
  if (!c.converged && !c.reason.empty())
    return c.reason;
  if (!c.converged)
    return fmt::format("{} did not converge in {} iterations", c.algorithm, c.iterations);
  for (std::size_t k = 0; k < c.steps_rad.size(); ++k)
    if (!std::isfinite(c.steps_rad[k]))
      return fmt::format("step {} is not a number ({})", k, c.steps_rad[k]);
  if (!std::isfinite(c.step_gain) || !(c.step_gain > 0.0))
    return fmt::format("step gain {}: the steps did not advance", c.step_gain);
  return {};
}

std::string format_step_calibration_toml(const StepCalibration& c) {
  std::string out;
  out += "# Phase-step calibration from interferograms (piezoshift psi calibrate; docs/psi.md)\n";
  out += "[psi_calibration]\n";
  out += fmt::format("algorithm = \"{}\"          # how the steps were recovered\n", c.algorithm);
  out += fmt::format("wavelength_nm = {:.6g}\n", c.wavelength_nm);
  out += fmt::format("frames = {}\n", c.steps_rad.size());
  out += fmt::format("nominal_step_rad = {:.9g}\n", c.nominal_step_rad);
  out += fmt::format("steps_rad = {}  # delta_k, delta_0 = 0\n", toml_array(c.steps_rad));
  out += fmt::format("steps_nm = {}   # mirror motion, delta_k lambda / (4 pi)\n",
                     toml_array(c.steps_nm));
  out += fmt::format("increments_nm = {}\n", toml_array(c.increments_nm));
  out += fmt::format(
      "step_gain = {:.9g}             # measured / nominal step (best line through 0)\n",
      c.step_gain);
  out += fmt::format("quadratic_per_rad = {:.9g}     # delta = g s k + q (s k)^2\n",
                     c.quadratic_per_rad);
  out += fmt::format("nonlinearity_pct = {:.6g}      # max deviation from the line, % of span\n",
                     c.nonlinearity_pct);
  out += fmt::format("rms_step_error_rad = {:.6g}\n", c.rms_step_error_rad);
  out += fmt::format("iterations = {}\nconverged = {}\n", c.iterations, c.converged);
  return out;
}

}  // namespace piezoshift::psi
