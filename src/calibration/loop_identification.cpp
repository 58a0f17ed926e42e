#include "piezoshift/calibration/loop_identification.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/core.h>
#include <Eigen/Dense>

#include "piezoshift/calibration/fit_error.hpp"
#include "piezoshift/plant/random.hpp"
#include "piezoshift/rig/bench.hpp"
#include "piezoshift/rig/validity.hpp"

namespace piezoshift::calibration {

std::complex<double> ArxModel::frequency_response(double frequency_Hz) const {
  const std::complex<double> zi =
      std::polar(1.0, -2.0 * std::numbers::pi * frequency_Hz * sample_time_s);
  std::complex<double> num = 0.0, den = 1.0, zk = 1.0;
  for (std::size_t j = 0; j < std::max(a.size(), b.size()); ++j) {
    zk *= zi;
    if (j < b.size())
      num += b[j] * zk;
    if (j < a.size())
      den -= a[j] * zk;
  }
  return num / den;
}

double ArxModel::dc_gain() const {
  double num = 0.0, den = 1.0;
  for (const double v : b)
    num += v;
  for (const double v : a)
    den -= v;
  return num / den;
}

double ArxModel::predict(std::span<const double> y_past, std::span<const double> u_past) const {
  double y = c;
  for (std::size_t i = 0; i < a.size() && i < y_past.size(); ++i)
    y += a[i] * y_past[i];
  for (std::size_t j = 0; j < b.size() && j < u_past.size(); ++j)
    y += b[j] * u_past[j];
  return y;
}

ArxModel fit_arx(std::span<const double> u, std::span<const double> y, int na, int nb,
                 double sample_time_s) {
  if (u.size() != y.size())
    throw FitError(fmt::format("ARX fit: {} inputs but {} outputs", u.size(), y.size()));
  if (na < 0 || nb < 1 || !(sample_time_s > 0.0))
    throw FitError("ARX fit: orders na >= 0, nb >= 1 and a sample time > 0 are needed");
  for (std::size_t k = 0; k < u.size(); ++k) {
    if (!std::isfinite(u[k]) || !std::isfinite(y[k]))
      throw FitError(fmt::format("ARX fit: sample {} is not finite", k));
  }
  const auto lag = static_cast<std::size_t>(std::max(na, nb));
  const auto unknowns = static_cast<std::size_t>(na + nb + 1);
  if (u.size() < lag + 10 * unknowns)
    throw FitError(fmt::format("ARX fit: {} samples, at least {} needed for na = {}, nb = {}",
                               u.size(), lag + 10 * unknowns, na, nb));
  const auto rows = static_cast<Eigen::Index>(u.size() - lag);
  Eigen::MatrixXd phi(rows, static_cast<Eigen::Index>(unknowns));
  Eigen::VectorXd target(rows);
  for (Eigen::Index r = 0; r < rows; ++r) {
    const std::size_t k = static_cast<std::size_t>(r) + lag;
    Eigen::Index col = 0;
    for (int i = 1; i <= na; ++i)
      phi(r, col++) = y[k - static_cast<std::size_t>(i)];
    for (int j = 1; j <= nb; ++j)
      phi(r, col++) = u[k - static_cast<std::size_t>(j)];
    phi(r, col) = 1.0;
    target(r) = y[k];
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(phi, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd sigma = svd.singularValues();
  if (!(sigma(sigma.size() - 1) > kRankRelTol * sigma(0)))
    throw FitError("ARX fit: the input does not excite the model (rank-deficient design)");
  const Eigen::VectorXd theta = svd.solve(target);
  ArxModel m;
  m.sample_time_s = sample_time_s;
  Eigen::Index col = 0;
  for (int i = 0; i < na; ++i)
    m.a.push_back(theta(col++));
  for (int j = 0; j < nb; ++j)
    m.b.push_back(theta(col++));
  m.c = theta(col);
  m.rms_residual_um = std::sqrt((phi * theta - target).squaredNorm() / static_cast<double>(rows));
  return m;
}

LoopIdentification identify_loop(const config::ProjectConfig& config,
                                 const control::SemiClosedLoopParams& controller,
                                 std::uint64_t seed, const LoopIdentificationOptions& o) {
  if (!(o.operating_um >= 0.0 && o.settle_s >= 0.0 && o.amplitude_um > 0.0 && o.duration_s > 0.0 &&
        o.hold_ticks >= 1))
    throw std::invalid_argument("identify_loop: bad options");
  rig::Bench bench(config, controller, seed);
  bench.drive_actuators(control::Vec3{o.operating_um, o.operating_um, o.operating_um});
  bench.run(o.settle_s);
  LoopIdentification r;
  const control::Vec3 u0 = bench.last_output().command_um;
  for (std::size_t i = 0; i < 3; ++i)
    r.operating_command_um[i] = u0[i];
  const auto ticks = static_cast<std::size_t>(std::llround(o.duration_s / bench.sample_time_s()));
  std::array<std::vector<double>, 3> u, y;
  plant::Rng rng(seed ^ 0x5052425355ULL);  // "PRBS": its own stream, the twin's untouched
  control::Vec3 level{};
  for (std::size_t i = 0; i < 3; ++i)
    level[i] = rng.normal() < 0.0 ? -1.0 : 1.0;
  const auto& scaling = controller.scaling;
  for (std::size_t k = 0; k < ticks; ++k) {
    if (k % static_cast<std::size_t>(o.hold_ticks) == 0) {
      for (std::size_t i = 0; i < 3; ++i)
        level[i] = rng.normal() < 0.0 ? -1.0 : 1.0;
    }
    control::Vec3 volts{};
    for (std::size_t i = 0; i < 3; ++i) {
      const double cmd = u0[i] + o.amplitude_um * level[i];
      volts[i] = scaling[i].um_to_dac(cmd);
      u[i].push_back(cmd);
    }
    bench.drive_open_loop(volts);
    bench.run(bench.sample_time_s());
    const runtime::CycleSample& s = bench.last_cycle();
    for (std::size_t i = 0; i < 3; ++i)
      y[i].push_back(scaling[i].sgs_to_um(s.ai_V[i]));
  }
  if (bench.faulted())
    throw rig::ProcedureFailed(
        fmt::format("loop identification: the safety supervisor tripped ({})",
                    runtime::to_string(bench.fault().reason)));
  // y[k] was read at the start of the tick that wrote u[k]: the pair the ARX model expects.
  for (std::size_t i = 0; i < 3; ++i)
    r.channel[i] = fit_arx(u[i], y[i], o.na, o.nb, bench.sample_time_s());
  return r;
}

std::complex<double> loop_frequency_response(const ArxModel& plant, const control::PidParams& pid,
                                             double frequency_Hz) {
  return runtime::pid_frequency_response(pid, frequency_Hz, plant.sample_time_s) *
         plant.frequency_response(frequency_Hz);
}

std::array<runtime::StabilityMargins, 3> pid_margins(const LoopIdentification& plant,
                                                     const control::PidParams& pid) {
  std::array<runtime::StabilityMargins, 3> out{};
  for (std::size_t i = 0; i < 3; ++i) {
    const ArxModel& m = plant.channel[i];
    out[i] = runtime::stability_margins(
        [&](double f) { return loop_frequency_response(m, pid, f); }, 0.01, 0.5 / m.sample_time_s);
  }
  return out;
}

std::array<runtime::StabilityMargins, 3> correction_margins(const LoopIdentification& plant,
                                                            const control::ImprovedParams& improved,
                                                            double ki) {
  std::array<runtime::StabilityMargins, 3> out{};
  for (std::size_t i = 0; i < 3; ++i) {
    control::PidParams c{};
    c.gains = {0.0, ki / improved.model[i].linear_weight, 0.0};
    const ArxModel& m = plant.channel[i];
    out[i] = runtime::stability_margins([&](double f) { return loop_frequency_response(m, c, f); },
                                        0.01, 0.5 / m.sample_time_s);
  }
  return out;
}

}  // namespace piezoshift::calibration
