#include "piezoshift/runtime/stability_margins.hpp"

#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <vector>

namespace piezoshift::runtime {

std::complex<double> pid_frequency_response(const control::PidParams& pid, double frequency_Hz,
                                            double sample_time_s) {
  const double theta = 2.0 * std::numbers::pi * frequency_Hz * sample_time_s;
  const std::complex<double> zi = std::polar(1.0, -theta);  // z^-1
  const std::complex<double> diff = 1.0 - zi;
  const control::PidGains& g = pid.gains;
  const double a = pid.derivative_filter;
  const std::complex<double> num =
      g.kp * diff + g.ki + g.kd * (1.0 - a) * diff * diff / (1.0 - a * zi);
  return num / diff;
}

namespace {

constexpr double kPi = std::numbers::pi;
constexpr int kGridPoints = 20000;
constexpr int kBisections = 60;

}  // namespace

StabilityMargins stability_margins(const std::function<std::complex<double>(double)>& loop,
                                   double f_min_Hz, double f_max_Hz) {
  if (!(f_min_Hz > 0.0 && f_max_Hz > f_min_Hz && std::isfinite(f_max_Hz)))
    throw std::invalid_argument("stability_margins: need 0 < f_min < f_max");
  std::vector<double> f(kGridPoints), mag(kGridPoints), phase(kGridPoints);
  const double ratio = std::log(f_max_Hz / f_min_Hz);
  for (int k = 0; k < kGridPoints; ++k) {
    const auto i = static_cast<std::size_t>(k);
    f[i] = f_min_Hz * std::exp(ratio * k / (kGridPoints - 1));
    const std::complex<double> l = loop(f[i]);
    if (!std::isfinite(l.real()) || !std::isfinite(l.imag()))
      throw std::invalid_argument("stability_margins: the loop's response is not finite");
    mag[i] = std::abs(l);
    phase[i] = std::arg(l);
    if (k > 0) {  // unwrap: the grid is dense enough that a true step is below pi
      double d = phase[i] - phase[i - 1];
      while (d > kPi)
        d -= 2.0 * kPi;
      while (d < -kPi)
        d += 2.0 * kPi;
      phase[i] = phase[i - 1] + d;
    }
  }
  // Refines a crossing of g(f) = 0 between grid points lo and hi by bisection on the response.
  const auto refine = [&](double lo, double hi, const auto& g) {
    const double g_lo = g(lo);
    for (int n = 0; n < kBisections; ++n) {
      const double mid = std::sqrt(lo * hi);
      if ((g(mid) < 0.0) == (g_lo < 0.0))
        lo = mid;
      else
        hi = mid;
    }
    return std::sqrt(lo * hi);
  };
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  StabilityMargins m{inf, nan, inf, nan};
  for (std::size_t i = 1; i < f.size(); ++i) {
    // Phase crossover: the unwrapped phase passes an odd multiple of -pi.
    const double n0 = std::floor((phase[i - 1] + kPi) / (2.0 * kPi));
    const double n1 = std::floor((phase[i] + kPi) / (2.0 * kPi));
    if (n0 != n1) {
      const double target = 2.0 * kPi * std::max(n0, n1) - kPi;
      const double base = phase[i - 1];
      const auto g = [&](double fr) {
        double d = std::arg(loop(fr)) - base;  // unwrap against the grid point below
        while (d > kPi)
          d -= 2.0 * kPi;
        while (d < -kPi)
          d += 2.0 * kPi;
        return base + d - target;
      };
      const double fc = refine(f[i - 1], f[i], g);
      const double gm = -20.0 * std::log10(std::abs(loop(fc)));
      if (gm < m.gain_margin_dB) {
        m.gain_margin_dB = gm;
        m.phase_crossover_Hz = fc;
      }
    }
    if ((mag[i - 1] - 1.0) * (mag[i] - 1.0) < 0.0) {
      const auto g = [&](double fr) { return std::abs(loop(fr)) - 1.0; };
      const double fc = refine(f[i - 1], f[i], g);
      double pm = 180.0 + std::arg(loop(fc)) * 180.0 / kPi;
      while (pm > 180.0)
        pm -= 360.0;
      while (pm <= -180.0)
        pm += 360.0;
      if (pm < m.phase_margin_deg) {
        m.phase_margin_deg = pm;
        m.gain_crossover_Hz = fc;
      }
    }
  }
  return m;
}

}  // namespace piezoshift::runtime
