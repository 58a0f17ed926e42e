#include "piezoshift/calibration/holding_gains.hpp"

#include <array>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "piezoshift/calibration/mode_identification.hpp"
#include "piezoshift/rig/bench.hpp"
#include "piezoshift/rig/validity.hpp"

namespace piezoshift::calibration {

namespace {

// Running rms of the second difference of each gauge over [from, to) ticks after the step.
struct RingWindow {
  std::size_t from = 0, to = 0;
  double sum2 = 0.0;
  std::size_t n = 0;
  void add(std::size_t tick, double d2) {
    if (tick >= from && tick < to) {
      sum2 += d2 * d2;
      ++n;
    }
  }
  double rms() const { return n > 0 ? std::sqrt(sum2 / static_cast<double>(n)) : 0.0; }
};

std::size_t ticks_of(double t_s, double T) {
  return static_cast<std::size_t>(std::llround(t_s / T));
}

// The loudest gauge's ring, identified as one sampled mode.
double ring_frequency_Hz(const std::array<std::vector<double>, 3>& ring, double rate_Hz) {
  std::size_t loudest = 0;
  double most = -1.0;
  for (std::size_t i = 0; i < ring.size(); ++i) {
    double e = 0.0;
    for (double d2 : ring[i])
      e += d2 * d2;
    if (e > most) {
      most = e;
      loudest = i;
    }
  }
  return identify_plate_mode(ring[loudest], rate_Hz).mode_Hz;
}

}  // namespace

RingTest ring_test(const config::ProjectConfig& config,
                   const control::SemiClosedLoopParams& controller, std::uint64_t seed,
                   const RingTestOptions& o) {
  rig::Bench bench(config, controller, seed, o.bench);
  const double T = bench.sample_time_s();
  control::Vec3 volts{};
  for (std::size_t i = 0; i < 3; ++i)
    volts[i] = controller.scaling[i].um_to_dac(o.operating_um);
  bench.drive_open_loop(volts);
  std::array<double, 3> y1{}, y2{};  // the last two readings per gauge
  // One tick, then per_gauge(i, reading, its second difference) for each gauge.
  const auto tick = [&](const auto& per_gauge) {
    bench.run(T);
    for (std::size_t i = 0; i < 3; ++i) {
      const double y = controller.scaling[i].sgs_to_um(bench.last_cycle().ai_V[i]);
      per_gauge(i, y, y - 2.0 * y1[i] + y2[i]);
      y2[i] = y1[i];
      y1[i] = y;
    }
  };
  RingWindow noise{ticks_of(0.5 * o.settle_s, T), ticks_of(o.settle_s, T) + 1};
  const std::size_t settle_ticks = ticks_of(o.settle_s, T);
  for (std::size_t k = 0; k < settle_ticks; ++k)
    tick([&](std::size_t, double, double d2) {
      if (k >= 2)
        noise.add(k, d2);
    });
  control::Vec3 target{};
  for (std::size_t i = 0; i < 3; ++i)
    target[i] = y1[i] + o.step_um;
  bench.drive_actuators(target);
  RingWindow early{ticks_of(o.early_s, T), ticks_of(o.early_s + o.window_s, T)};
  RingWindow late{ticks_of(o.late_s, T), ticks_of(o.late_s + o.window_s, T)};
  RingTest r;
  std::array<std::vector<double>, 3> ring{};  // each gauge's second difference from the step on
  for (std::size_t k = 0; k < late.to; ++k) {
    tick([&](std::size_t i, double y, double d2) {
      early.add(k, d2);
      late.add(k, d2);
      ring[i].push_back(d2);
      r.aborted = r.aborted || std::fabs(y - target[i]) > o.abort_um;
    });
    if (r.aborted || bench.faulted()) {
      r.aborted = true;
      bench.drive_open_loop(volts);  // opened by the procedure: nothing more is learned
      break;
    }
  }
  r.noise_ring_um = noise.rms();
  r.early_ring_um = early.rms();
  r.late_ring_um = late.rms();
  r.ring_Hz = ring_frequency_Hz(ring, 1.0 / T);
  r.holds = !r.aborted && (r.late_ring_um <= o.decay_ratio * r.early_ring_um ||
                           r.late_ring_um <= o.noise_factor * r.noise_ring_um);
  return r;
}

HoldingGains holding_gains(const config::ProjectConfig& config,
                           const control::SemiClosedLoopParams& controller, std::uint64_t seed,
                           const HoldingGainsOptions& o, const std::string& what) {
  HoldingGains h;
  const control::PidGains asked = controller.pid_params().gains;  // per sample at its rate
  control::SemiClosedLoopParams trial = controller;
  trial.gains_sample_time_s = controller.sample_time_s;
  for (double s = 1.0; s >= o.min_scale; s *= o.step_factor) {
    const double m = s * o.margin_factor;
    trial.gains = {m * asked.kp, m * asked.ki, m * asked.kd};
    h.test = ring_test(config, trial, seed, o.ring);
    if (h.tests == 0)
      h.first = h.test;
    ++h.tests;
    if (h.test.holds) {
      h.scale = s;
      h.gains = {s * asked.kp, s * asked.ki, s * asked.kd};
      return h;
    }
  }
  throw rig::ProcedureFailed(fmt::format(
      "{}: the plant is outside what the procedure can hold: its PID gains (kp {:g}, ki {:g}, "
      "kd {:g} per sample at {:g} s), scaled down to {:g} of themselves, still ring up at "
      "{:g} x (the last test: ring {:.2g} um, then {:.2g} um{})",
      what, asked.kp, asked.ki, asked.kd, controller.sample_time_s, o.min_scale, o.margin_factor,
      h.test.early_ring_um, h.test.late_ring_um, h.test.aborted ? ", opened by the test" : ""));
}

}  // namespace piezoshift::calibration
