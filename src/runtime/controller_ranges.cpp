#include "piezoshift/runtime/controller_ranges.hpp"

#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <utility>

#include <fmt/core.h>
#include <Eigen/Dense>

#include "piezoshift/control/parameter_check.hpp"
#include "piezoshift/core/bounds.hpp"
#include "piezoshift/runtime/stability_margins.hpp"

namespace piezoshift::runtime {

namespace {

// Checks each number of the list against its range, naming the first one outside it.
class RangeCheck {
 public:
  FieldProblem problem;

  void operator()(std::string_view section, std::string_view key, const double& v,
                  const core::Bounds& b, std::string_view) {
    note(section, key, core::range_problem(key, v, b));
  }
  void operator()(std::string_view section, std::string_view key, const std::size_t& v,
                  const core::Bounds& b, std::string_view) {
    note(section, key, core::range_problem(key, static_cast<std::int64_t>(v), b));
  }
  template <class Value, class Count>
  void operator()(std::string_view section, std::string_view key, const ListField<Value, Count>& f,
                  const core::Bounds& b, std::string_view) {
    if (*f.count > f.capacity) {
      note(section, key, fmt::format("{}: {} values, at most {}", key, *f.count, f.capacity));
      return;
    }
    for (std::size_t i = 0; i < *f.count && problem.empty(); ++i)
      note(section, key, core::range_problem(fmt::format("{}[{}]", key, i), f.values[i], b));
  }

 private:
  void note(std::string_view section, std::string_view key, const std::string& why) {
    if (problem.empty() && !why.empty())
      problem = {std::string(section), std::string(key), fmt::format("[{}] {}", section, why)};
  }
};

// p's least slope where the gauges are read through it: flatter turns 1 nm of gauge into 100 nm
// of position.
constexpr double kMinInverseSlope = 0.01;

FieldProblem on(std::string key, std::string why) {
  return {"controller", std::move(key), fmt::format("[controller] {}", why)};
}

// The lowest and highest of p'(z) = 3 p3 z^2 + 2 p2 z + p1 over [lo, hi]: a parabola's extremes
// are at an end or at its vertex.
std::pair<double, double> slope_range(const control::CubicPolynomial& p, double lo, double hi) {
  const auto slope = [&p](double z) { return 3.0 * p.p3 * z * z + 2.0 * p.p2 * z + p.p1; };
  double low = std::min(slope(lo), slope(hi));
  double high = std::max(slope(lo), slope(hi));
  if (p.p3 != 0.0) {
    const double vertex = -p.p2 / (3.0 * p.p3);
    if (vertex > lo && vertex < hi) {
      low = std::min(low, slope(vertex));
      high = std::max(high, slope(vertex));
    }
  }
  return {low, high};
}

FieldProblem polynomial_problem(const control::CubicPolynomial& p) {
  if (!std::isfinite(p.p0) || !std::isfinite(p.p1) || !std::isfinite(p.p2) || !std::isfinite(p.p3))
    return on("p", "p: a coefficient is not a finite number");
  const std::string coefficients = fmt::format("p = [{}, {}, {}, {}]", p.p3, p.p2, p.p1, p.p0);
  // The slope over the stroke is the command's gain: within the band the stage can be.
  const auto [low, high] = slope_range(p, 0.0, kStrokeUm);
  if (!kPolynomialSlope.contains(low) || !kPolynomialSlope.contains(high))
    return on("p",
              fmt::format("{}: its slope over the 0 to {} um stroke runs from {:.4g} to {:.4g} "
                          "um per um, must be {} (docs/calibration.md)",
                          coefficients, kStrokeUm, low, high, kPolynomialSlope.describe()));
  // Where the host inverts it (host/stage_model.hpp: -z_max to 2 z_max) it must still rise, by
  // enough that dividing by its slope there cannot overflow (POS? printed inf or -nan).
  const double lowest = slope_range(p, -kStrokeUm, 2.0 * kStrokeUm).first;
  if (!(lowest >= kMinInverseSlope))
    return on("p",
              fmt::format("{}: the cubic must rise over [{}, {}] um, where the gauges' "
                          "positions are read through it (its slope reaches {:.4g}, at least {:g})",
                          coefficients, -kStrokeUm, 2.0 * kStrokeUm, lowest, kMinInverseSlope));
  return {};
}

FieldProblem matrix_problem(const control::Mat3& a) {
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      const double v = a[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)];
      if (!std::isfinite(v) || std::fpclassify(v) == FP_SUBNORMAL)
        return on("A", fmt::format("A[{}][{}] = {}: not a finite, normal number", r, c, v));
      if (!kMatrixEntry.contains(v))
        return on("A", fmt::format("A[{}][{}] = {}: must be {} (docs/calibration.md)", r, c, v,
                                   kMatrixEntry.describe()));
      m(r, c) = v;
    }
  const Eigen::Vector3d sv = Eigen::JacobiSVD<Eigen::Matrix3d>(m).singularValues();
  const double condition = sv(2) > 0.0 ? sv(0) / sv(2) : std::numeric_limits<double>::infinity();
  if (!(condition <= kMaxMatrixCondition))
    return on("A", fmt::format("A: condition number {:.4g} (at most {:g}: a singular or nearly "
                               "singular A cannot give the positions the gauges show)",
                               condition, kMaxMatrixCondition));
  for (int r = 0; r < 3; ++r) {
    const double sum = m.row(r).sum();
    if (!kMatrixRowSum.contains(sum))
      return on("A", fmt::format("A: row {} sums to {:.4g} (actuator {}'s gauge um per um of plate "
                                 "piston), must be {} (docs/calibration.md)",
                                 r, sum, r + 1, kMatrixRowSum.describe()));
  }
  return {};
}

}  // namespace

std::string model_section(std::size_t channel) {
  return fmt::format("improved.channel{}", channel + 1);
}

double nominal_gain_margin_dB(const control::SemiClosedLoopParams& params) {
  const control::PidParams pid = params.pid_params();
  const double t = params.sample_time_s;
  const auto loop = [&pid, t](double f) {
    // G behind the DAQ contract's two ticks: G z^-2 = G e^{-j 2 w T}.
    const std::complex<double> delay =
        std::polar(kNominalPlantGain, -2.0 * 2.0 * std::numbers::pi * f * t);
    return pid_frequency_response(pid, f, t) * delay;
  };
  return stability_margins(loop, 0.01, 0.5 / t).gain_margin_dB;
}

double own_sample_time_s(const control::SemiClosedLoopParams& params) {
  return params.kind == control::ControllerKind::kImproved ? params.improved.sample_time_s
                                                           : params.gains_sample_time_s;
}

FieldProblem controller_field_problem(const control::SemiClosedLoopParams& in,
                                      double loop_sample_time_s) {
  control::SemiClosedLoopParams params = in;
  params.sample_time_s = loop_sample_time_s;
  RangeCheck check;
  visit_controller_fields(params, check);
  if (params.kind == control::ControllerKind::kImproved) {
    visit_improved_fields(params.improved, check);
    for (std::size_t i = 0; i < control::kChannels; ++i)
      visit_model_fields(params.improved.model[i], model_section(i), check);
  }
  if (!check.problem.empty())
    return check.problem;
  const control::ParamsProblem loop = control::params_problem(params, loop_sample_time_s);
  if (loop != control::ParamsProblem::kNone)
    return {"controller", "", fmt::format("the loop cannot run it: {}", control::to_string(loop))};
  if (FieldProblem why = polynomial_problem(params.polynomial); !why.empty())
    return why;
  if (FieldProblem why = matrix_problem(params.matrix.a); !why.empty())
    return why;
  double margin_dB = 0.0;
  try {
    margin_dB = nominal_gain_margin_dB(params);
  } catch (const std::invalid_argument& e) {
    return on("kp", fmt::format("kp, ki, kd: {}", e.what()));
  }
  if (!(margin_dB > 0.0))
    return on("kp", fmt::format("kp = {}, ki = {}, kd = {}: unstable on the nominal inner loop "
                                "(gain margin {:.2f} dB with a plant gain of {} behind two ticks "
                                "of delay; the gains must keep it above 0 dB, "
                                "docs/calibration.md)",
                                params.gains.kp, params.gains.ki, params.gains.kd, margin_dB,
                                kNominalPlantGain));
  return {};
}

std::string controller_problem(const control::SemiClosedLoopParams& params,
                               double loop_sample_time_s) {
  return controller_field_problem(params, loop_sample_time_s).why;
}

FieldProblem travel_problem(std::optional<double> z_max_um, std::optional<double> z_min_um) {
  RangeCheck check;
  double z_max = z_max_um.value_or(kStrokeUm), z_min = z_min_um.value_or(0.0);
  visit_travel_fields(z_max, z_min, check);
  if (!check.problem.empty())
    return check.problem;
  if (z_max_um && z_min_um && !(*z_min_um < *z_max_um))
    return {
        "travel", "z_min_um",
        fmt::format("[travel] z_min_um = {} must be below z_max_um = {}", *z_min_um, *z_max_um)};
  return {};
}

}  // namespace piezoshift::runtime
