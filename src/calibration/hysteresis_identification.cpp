#include "piezoshift/calibration/hysteresis_identification.hpp"

#include <fmt/format.h>
#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <vector>

#include "piezoshift/calibration/compressed_least_squares.hpp"
#include "piezoshift/calibration/fit_error.hpp"

namespace piezoshift::calibration {

namespace {

using control::HysteresisCreepParams;

// Operator outputs s_j(u_k) with unit weights, from rest at 0.
Eigen::MatrixXd play_outputs(std::span<const double> u, const HysteresisCreepParams& p) {
  Eigen::MatrixXd s(static_cast<Eigen::Index>(u.size()), static_cast<Eigen::Index>(p.operators));
  std::vector<double> state(p.operators, 0.0);
  for (std::size_t k = 0; k < u.size(); ++k) {
    for (std::size_t j = 0; j < p.operators; ++j) {
      double v = state[j];
      v = std::max(v, u[k] - p.threshold_um[j]);
      v = std::min(v, u[k]);
      state[j] = v;
      s(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(j)) = v;
    }
  }
  return s;
}

// sum_m (c_m - h) with c_m the unit-gain first-order terms driven by h, from rest.
Eigen::VectorXd creep_regressor(const Eigen::VectorXd& h, const HysteresisCreepParams& p,
                                double sample_time_s) {
  std::vector<double> a(p.creep_terms), c(p.creep_terms, 0.0);
  for (std::size_t m = 0; m < p.creep_terms; ++m)
    a[m] = std::exp(-sample_time_s / p.creep_time_constant_s[m]);
  Eigen::VectorXd z(h.size());
  for (Eigen::Index k = 0; k < h.size(); ++k) {
    double sum = 0.0;
    for (std::size_t m = 0; m < p.creep_terms; ++m) {
      c[m] = a[m] * c[m] + (1.0 - a[m]) * h(k);
      sum += c[m] - h(k);
    }
    z(k) = sum;
  }
  return z;
}

std::size_t min_fit_rows(const HysteresisFitOptions& o) {
  return 20 * (o.operators + 4) + o.max_delay_ticks;
}

void check_fit_input(std::span<const double> command_um, std::span<const double> gauge_um,
                     double sample_time_s, const HysteresisFitOptions& o) {
  if (command_um.size() != gauge_um.size())
    throw FitError(fmt::format("hysteresis fit: {} commands but {} gauge readings",
                               command_um.size(), gauge_um.size()));
  for (std::size_t k = 0; k < command_um.size(); ++k)
    if (!std::isfinite(command_um[k]) || !std::isfinite(gauge_um[k]))
      throw FitError(fmt::format("hysteresis fit: a non-finite value at sample {}", k));
  if (o.operators < 1 || o.operators > control::kMaxModelOperators || !(o.command_span_um > 0.0) ||
      !(o.creep_shortest_s > 0.0) || !(o.creep_longest_s >= o.creep_shortest_s) ||
      o.creep_terms_per_decade < 1 || !(sample_time_s > 0.0))
    throw FitError("hysteresis fit: invalid options");
  const std::size_t min_rows = min_fit_rows(o);
  if (command_um.size() < min_rows)
    throw FitError(
        fmt::format("hysteresis fit: {} samples, at least {} needed", command_um.size(), min_rows));
}

// The model's fixed grid, no weights yet: operators evenly spaced over the command span (shifted
// by threshold_phase of a spacing), creep time constants per decade from creep_shortest_s.
HysteresisCreepParams model_grid(const HysteresisFitOptions& o, double threshold_phase) {
  HysteresisCreepParams base{};
  base.operators = o.operators;
  for (std::size_t j = 0; j < o.operators; ++j)
    base.threshold_um[j] = (static_cast<double>(j) + threshold_phase) * o.command_span_um /
                           static_cast<double>(o.operators);
  const double decades = std::log10(o.creep_longest_s / o.creep_shortest_s);
  base.creep_terms = std::min<std::size_t>(
      control::kMaxCreepTerms, static_cast<std::size_t>(std::floor(
                                   decades * static_cast<double>(o.creep_terms_per_decade))) +
                                   1);
  for (std::size_t m = 0; m < base.creep_terms; ++m)
    base.creep_time_constant_s[m] =
        o.creep_shortest_s *
        std::pow(10.0, static_cast<double>(m) / static_cast<double>(o.creep_terms_per_decade));
  return base;
}

// Rows kept: not within exclude_after_jump_s of a jump of the command (by the row's own u).
std::vector<char> quiet_samples(std::span<const double> command_um, double sample_time_s,
                                const HysteresisFitOptions& o) {
  std::vector<char> quiet(command_um.size(), 1);
  const auto hold = static_cast<std::size_t>(std::ceil(o.exclude_after_jump_s / sample_time_s));
  std::size_t since = hold;
  for (std::size_t k = 0; k < command_um.size(); ++k) {
    if (k > 0 && std::fabs(command_um[k] - command_um[k - 1]) > o.jump_um)
      since = 0;
    quiet[k] = since >= hold ? 1 : 0;
    ++since;
  }
  return quiet;
}

// What the fit at every delay shares.
struct FitProblem {
  std::span<const double> command_um;
  std::span<const double> gauge_um;
  double sample_time_s;
  const HysteresisFitOptions& o;
  HysteresisCreepParams base;  //!< model_grid()
  Eigen::MatrixXd s_all;       //!< the operators' outputs on the whole command
  std::vector<char> quiet;     //!< quiet_samples()
  std::size_t min_rows;
};

// The samples fitted at one delay: y_k is the gauge D ticks after the command u_k.
struct DelayedSamples {
  Eigen::VectorXd u, y;
  std::vector<Eigen::Index> rows;  //!< the quiet ones
};

DelayedSamples delayed_samples(const FitProblem& f, std::size_t d) {
  const auto n = static_cast<Eigen::Index>(f.command_um.size() - d);
  const auto di = static_cast<Eigen::Index>(d);
  DelayedSamples s{Eigen::VectorXd(n), Eigen::VectorXd(n), {}};
  for (Eigen::Index k = 0; k < n; ++k) {
    s.y(k) = f.gauge_um[static_cast<std::size_t>(k + di)];
    s.u(k) = f.command_um[static_cast<std::size_t>(k)];
  }
  for (Eigen::Index k = 0; k < n; ++k)
    if (f.quiet[static_cast<std::size_t>(k)] != 0)
      s.rows.push_back(k);
  if (s.rows.size() < f.min_rows)
    throw FitError(fmt::format("hysteresis fit: {} quiet samples, at least {} needed",
                               s.rows.size(), f.min_rows));
  return s;
}

// The fixed columns (1, u, the operators) on the rows fitted, compressed once.
CompressedLeastSquares fixed_columns(const FitProblem& f, const DelayedSamples& s) {
  Eigen::MatrixXd B(static_cast<Eigen::Index>(s.rows.size()), 2 + f.o.operators);
  Eigen::VectorXd y_rows(static_cast<Eigen::Index>(s.rows.size()));
  for (std::size_t r = 0; r < s.rows.size(); ++r) {
    const auto ri = static_cast<Eigen::Index>(r);
    B(ri, 0) = 1.0;
    B(ri, 1) = s.u(s.rows[r]);
    for (std::size_t j = 0; j < f.o.operators; ++j)
      B(ri, static_cast<Eigen::Index>(2 + j)) = f.s_all(s.rows[r], static_cast<Eigen::Index>(j));
    y_rows(ri) = s.y(s.rows[r]);
  }
  return CompressedLeastSquares(B, y_rows);
}

// The creep column on the rows fitted: the creep regressor run on p's hysteresis.
Eigen::VectorXd creep_column(const FitProblem& f, const DelayedSamples& s,
                             const HysteresisCreepParams& p) {
  Eigen::VectorXd h = p.linear_weight * s.u;
  for (std::size_t j = 0; j < f.o.operators; ++j)
    h += p.weight[j] * f.s_all.col(static_cast<Eigen::Index>(j)).head(s.u.size());
  const Eigen::VectorXd z = creep_regressor(h, p, f.sample_time_s);
  Eigen::VectorXd z_rows(static_cast<Eigen::Index>(s.rows.size()));
  for (std::size_t r = 0; r < s.rows.size(); ++r)
    z_rows(static_cast<Eigen::Index>(r)) = z(s.rows[r]);
  return z_rows;
}

// Least squares on 1, u, the kept operators (and z when not empty), dropping the operator with
// the most negative weight until none is negative; kept is left with the operators kept.
LeastSquaresSolution solve_non_negative(const CompressedLeastSquares& ls,
                                        std::vector<std::size_t>& kept,
                                        const Eigen::VectorXd& z_rows) {
  for (;;) {
    std::vector<std::size_t> cols{0, 1};
    for (const std::size_t j : kept)
      cols.push_back(2 + j);
    LeastSquaresSolution sol = ls.solve(cols, z_rows);
    std::size_t worst = kept.size();
    double worst_w = 0.0;
    for (std::size_t j = 0; j < kept.size(); ++j)
      if (sol.x(static_cast<Eigen::Index>(2 + j)) < worst_w) {
        worst_w = sol.x(static_cast<Eigen::Index>(2 + j));
        worst = j;
      }
    if (worst == kept.size())
      return sol;
    kept.erase(kept.begin() + static_cast<std::ptrdiff_t>(worst));
  }
}

HysteresisFit fit_at_delay(const FitProblem& f, std::size_t d) {
  const DelayedSamples s = delayed_samples(f, d);
  const CompressedLeastSquares ls = fixed_columns(f, s);
  LeastSquaresSolution sol;
  HysteresisCreepParams p = f.base;
  std::size_t dropped = 0;
  std::vector<std::size_t> kept;
  // Pass 0 without creep; then the creep regressor run on the previous pass's hysteresis, and
  // all together again, max_creep_passes times or until the creep gain settles (the creep is
  // bilinear in the weights and its gain; each pass is the exact least squares given the last
  // pass's h).
  for (std::size_t pass = 0; pass <= f.o.max_creep_passes; ++pass) {
    Eigen::VectorXd z_rows;
    if (pass > 0)
      z_rows = creep_column(f, s, p);
    // Pass 1 keeps the operators pass 0 kept; a later pass starts from all again (an operator
    // dropped while the creep was missing may be needed once it is modelled).
    if (pass != 1) {
      kept.resize(f.o.operators);
      for (std::size_t j = 0; j < f.o.operators; ++j)
        kept[j] = j;
    }
    sol = solve_non_negative(ls, kept, z_rows);
    const double last_gain = p.creep_gain;
    p = f.base;
    p.offset_um = sol.x(0);
    p.linear_weight = sol.x(1);
    p.weight = {};
    for (std::size_t j = 0; j < kept.size(); ++j)
      p.weight[kept[j]] = sol.x(static_cast<Eigen::Index>(2 + j));
    p.creep_gain = pass > 0 ? sol.x(sol.x.size() - 1) : 0.0;
    dropped = f.o.operators - kept.size();
    if (pass > 1 && std::fabs(p.creep_gain - last_gain) <= f.o.creep_gain_tolerance)
      break;
  }
  HysteresisFit fit;
  fit.params = p;
  fit.delay_ticks = d;
  fit.rms_residual_um = sol.rms;
  fit.operators_dropped = dropped;
  fit.samples_fitted = s.rows.size();
  return fit;
}

HysteresisFit fit_with_creep_from(std::span<const double> command_um,
                                  std::span<const double> gauge_um, double sample_time_s,
                                  const HysteresisFitOptions& o, double threshold_phase) {
  check_fit_input(command_um, gauge_um, sample_time_s, o);
  const HysteresisCreepParams base = model_grid(o, threshold_phase);
  const FitProblem problem{command_um,
                           gauge_um,
                           sample_time_s,
                           o,
                           base,
                           play_outputs(command_um, base),
                           quiet_samples(command_um, sample_time_s, o),
                           min_fit_rows(o)};
  HysteresisFit best;
  best.rms_residual_um = std::numeric_limits<double>::infinity();
  for (std::size_t d = 0; d <= o.max_delay_ticks; ++d) {
    const HysteresisFit fit = fit_at_delay(problem, d);
    if (fit.rms_residual_um < best.rms_residual_um)
      best = fit;
  }
  if (!(best.params.linear_weight > 0.0))
    throw FitError("hysteresis fit: the gauges do not follow the command (slope <= 0)");
  return best;
}

}  // namespace

HysteresisFit fit_hysteresis_creep(std::span<const double> command_um,
                                   std::span<const double> gauge_um, double sample_time_s,
                                   const HysteresisFitOptions& o) {
  // The creep law's short end is identified too: a log creep that the stack does not have at
  // its shortest time constants makes the model expect a fast rise after every step.
  HysteresisFit best;
  best.rms_residual_um = std::numeric_limits<double>::infinity();
  const std::size_t phases = std::max<std::size_t>(o.threshold_phase_candidates, 1);
  for (std::size_t i = 0; i < std::max<std::size_t>(o.creep_start_candidates, 1); ++i) {
    HysteresisFitOptions oi = o;
    oi.creep_shortest_s =
        o.creep_shortest_s *
        std::pow(10.0, static_cast<double>(i) / static_cast<double>(o.creep_terms_per_decade));
    if (i > 0 && !(oi.creep_shortest_s <= o.creep_longest_s))
      break;
    for (std::size_t k = 0; k < phases; ++k) {
      // 1/2 first (the centred grid), then on by 1/phases of a spacing, wrapped into (0, 1].
      double phase = 0.5 + static_cast<double>(k) / static_cast<double>(phases);
      if (phase > 1.0)
        phase -= 1.0;
      const HysteresisFit f = fit_with_creep_from(command_um, gauge_um, sample_time_s, oi, phase);
      if (f.rms_residual_um < best.rms_residual_um)
        best = f;
    }
  }
  return best;
}

}  // namespace piezoshift::calibration
