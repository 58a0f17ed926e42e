#include "piezoshift/calibration/rate_verdict.hpp"

#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "piezoshift/control/setpoint_shaper.hpp"

namespace piezoshift::calibration {

namespace {

// The 1 ms exposures the lambda/8 step is judged on (experiments' phase step).
constexpr double kExposure_s = 1e-3;

double fold_Hz(double mode_Hz, double rate_Hz) {
  const double f = std::fmod(mode_Hz, rate_Hz);
  return f > 0.5 * rate_Hz ? rate_Hz - f : f;
}

}  // namespace

double shaped_phase_step_s(double mode_Hz, double rate_Hz, int delay_ticks) {
  if (!(mode_Hz > 0.0) || !(rate_Hz > 0.0))
    return std::numeric_limits<double>::quiet_NaN();
  const double theta = 2.0 * std::numbers::pi * fold_Hz(mode_Hz, rate_Hz) / rate_Hz;
  if (!(theta > 1e-9))
    return std::numeric_limits<double>::infinity();
  const control::ShaperParams taps = control::design_mode_shaper(mode_Hz, 1.0 / rate_Hz, 1.0);
  // The shaper's own span where it can place the mode, else the shortest positive taps' bound.
  const double span =
      taps.taps > 1 ? static_cast<double>(taps.taps - 1) : std::ceil(std::numbers::pi / theta);
  const double step_s = (static_cast<double>(delay_ticks) + span) / rate_Hz;
  return rate_Hz > 1.0 / kExposure_s + 1e-9 ? step_s + kExposure_s : step_s;
}

RateVerdict judge_loop_rate(double mode_Hz, double loop_rate_Hz, int delay_ticks, double target_s) {
  RateVerdict v;
  v.mode_Hz = mode_Hz;
  v.loop_rate_Hz = loop_rate_Hz;
  v.target_s = target_s;
  if (!(mode_Hz > 0.0) || !(loop_rate_Hz > 0.0))
    return v;
  v.folded_Hz = fold_Hz(mode_Hz, loop_rate_Hz);
  v.step_s = shaped_phase_step_s(mode_Hz, loop_rate_Hz, delay_ticks);
  v.mode_is_the_limit = v.step_s > target_s * (1.0 + 1e-9);
  if (!v.mode_is_the_limit)
    return v;
  for (const int k : kRateMultiples) {
    const double rate = k * loop_rate_Hz;
    const double step = shaped_phase_step_s(mode_Hz, rate, delay_ticks);
    if (step <= target_s * (1.0 + 1e-9)) {
      v.faster_rate_Hz = rate;
      v.faster_step_s = step;
      break;
    }
  }
  return v;
}

std::string RateVerdict::text() const {
  if (!mode_is_the_limit)
    return "";
  const std::string step =
      std::isfinite(step_s) ? fmt::format("{:.0f} ms", 1e3 * step_s) : std::string("no settling");
  std::string s = fmt::format(
      "the plate's mode at {:.0f} Hz folds to {:.0f} Hz at the {:g} kHz loop rate: the "
      "lambda/8 step it allows there is {} (target {:g} ms)",
      mode_Hz, folded_Hz, 1e-3 * loop_rate_Hz, step, 1e3 * target_s);
  if (faster_rate_Hz > 0.0)
    s += fmt::format("; at {:g} kHz it is {:.1f} ms", 1e-3 * faster_rate_Hz, 1e3 * faster_step_s);
  else
    s += "; no rate up to 10 x this one meets it";
  return s;
}

}  // namespace piezoshift::calibration
