#include "piezoshift/calibration/controller_ranges.hpp"

#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <fmt/core.h>
#include <Eigen/Dense>

#include "piezoshift/calibration/stability_margins.hpp"
#include "piezoshift/control/parameter_check.hpp"
#include "piezoshift/core/bounds.hpp"

namespace piezoshift::calibration {

namespace {

// Checks each number of the list against its range, naming the first one outside it.
class RangeCheck {
 public:
  std::string problem;

  void operator()(std::string_view section, std::string_view key, const double& v,
                  const core::Bounds& b, std::string_view) {
    note(section, core::range_problem(key, v, b));
  }
  void operator()(std::string_view section, std::string_view key, const std::size_t& v,
                  const core::Bounds& b, std::string_view) {
    note(section, core::range_problem(key, static_cast<std::int64_t>(v), b));
  }
  template <class Value, class Count>
  void operator()(std::string_view section, std::string_view key, const ListField<Value, Count>& f,
                  const core::Bounds& b, std::string_view) {
    if (*f.count > f.capacity) {
      note(section, fmt::format("{}: {} values, at most {}", key, *f.count, f.capacity));
      return;
    }
    for (std::size_t i = 0; i < *f.count && problem.empty(); ++i)
      note(section, core::range_problem(fmt::format("{}[{}]", key, i), f.values[i], b));
  }

 private:
  void note(std::string_view section, const std::string& why) {
    if (problem.empty() && !why.empty())
      problem = fmt::format("[{}] {}", section, why);
  }
};

std::string polynomial_problem(const control::CubicPolynomial& p) {
  if (!std::isfinite(p.p0) || !std::isfinite(p.p1) || !std::isfinite(p.p2) || !std::isfinite(p.p3))
    return "[controller] p: a coefficient is not a finite number";
  // p'(z) = 3 p3 z^2 + 2 p2 z + p1 is a parabola: its minimum over [0, stroke] is at an end or at
  // its vertex.
  constexpr double stroke_um = 16.0;  // the nominal stroke, Section 2.1
  const auto slope = [&p](double z) { return 3.0 * p.p3 * z * z + 2.0 * p.p2 * z + p.p1; };
  double lowest = std::min(slope(0.0), slope(stroke_um));
  if (p.p3 != 0.0) {
    const double vertex = -p.p2 / (3.0 * p.p3);
    if (vertex > 0.0 && vertex < stroke_um)
      lowest = std::min(lowest, slope(vertex));
  }
  if (!(lowest > 0.0))
    return fmt::format(
        "[controller] p = [{}, {}, {}, {}]: the cubic must rise over the 0 to {} um stroke (its "
        "slope reaches {:.4g})",
        p.p3, p.p2, p.p1, p.p0, stroke_um, lowest);
  return "";
}

std::string matrix_problem(const control::Mat3& a) {
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      const double v = a[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)];
      if (!std::isfinite(v) || std::fpclassify(v) == FP_SUBNORMAL)
        return fmt::format("[controller] A[{}][{}] = {}: not a finite, normal number", r, c, v);
      m(r, c) = v;
    }
  const Eigen::Vector3d sv = Eigen::JacobiSVD<Eigen::Matrix3d>(m).singularValues();
  const double condition = sv(2) > 0.0 ? sv(0) / sv(2) : std::numeric_limits<double>::infinity();
  if (!(condition <= kMaxMatrixCondition))
    return fmt::format(
        "[controller] A: condition number {:.4g} (at most {:g}: a singular or nearly singular A "
        "cannot give the positions the gauges show)",
        condition, kMaxMatrixCondition);
  return "";
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

std::string controller_problem(const control::SemiClosedLoopParams& in, double loop_sample_time_s) {
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
    return fmt::format("the loop cannot run it: {}", control::to_string(loop));
  if (std::string why = polynomial_problem(params.polynomial); !why.empty())
    return why;
  if (std::string why = matrix_problem(params.matrix.a); !why.empty())
    return why;
  double margin_dB = 0.0;
  try {
    margin_dB = nominal_gain_margin_dB(params);
  } catch (const std::invalid_argument& e) {
    return fmt::format("[controller] kp, ki, kd: {}", e.what());
  }
  if (!(margin_dB > 0.0))
    return fmt::format(
        "[controller] kp = {}, ki = {}, kd = {}: unstable on the nominal inner loop (gain margin "
        "{:.2f} dB with a plant gain of {} behind two ticks of delay; the gains must keep it "
        "above 0 dB, docs/calibration.md)",
        params.gains.kp, params.gains.ki, params.gains.kd, margin_dB, kNominalPlantGain);
  return "";
}

}  // namespace piezoshift::calibration
