#include "piezoshift/experiments/metrics_step_response.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "../calibration/gaussian_noise.hpp"

namespace piezoshift::experiments {
namespace {

constexpr double kTau = 0.01;   // [s]
constexpr double kStep = 11.0;  // [um], the paper's Figure 10 step
constexpr double kDt = 1e-4;    // [s]
constexpr double kT0 = 0.005;   // step instant [s]

struct Record {
  std::vector<double> t, y;
};

// y = 0 before t0, then kStep (1 - exp(-(t - t0) / tau)) for 20 tau.
Record first_order() {
  Record r;
  for (int k = 0; k * kDt <= kT0 + 20 * kTau + 1e-12; ++k) {
    const double t = k * kDt;
    r.t.push_back(t);
    r.y.push_back(t < kT0 ? 0.0 : kStep * (1.0 - std::exp(-(t - kT0) / kTau)));
  }
  return r;
}

TEST(StepResponse, FirstOrderClosedFormRiseAndSettlingTimes) {
  const Record r = first_order();
  StepResponseOptions o;
  o.step_time_s = kT0;
  const StepResponseMetrics m = step_response_metrics(r.t, r.y, o);
  EXPECT_NEAR(m.initial_um, 0.0, 0.0);
  EXPECT_NEAR(m.final_um, kStep, 1e-6);  // exp(-18) * 11 um after 20 tau
  // 10 % at tau ln(10/9), 90 % at tau ln 10: rise = tau ln 9 = 2.1972 tau.
  EXPECT_NEAR(m.t10_s - kT0, kTau * std::log(10.0 / 9.0), 1e-3 * kTau);
  EXPECT_NEAR(m.rise_time_s, kTau * std::log(9.0), 1e-3 * kTau);
  EXPECT_NEAR(m.rise_time_s / kTau, 2.197, 1e-3);
  // 2 % band: exp(-t/tau) = 0.02 -> t = tau ln 50 = 3.912 tau.
  EXPECT_NEAR(m.settling_time_pct_s / kTau, std::log(50.0), 1e-3);
  EXPECT_NEAR(m.settling_time_pct_s / kTau, 3.912, 1e-3);
  // +-10 nm band: 11 um exp(-t/tau) = 0.01 um -> t = tau ln 1100 = 7.003 tau.
  EXPECT_NEAR(m.settling_time_abs_s / kTau, std::log(1100.0), 1e-3);
  // y_inf is the mean of the last 10 % (18..20 tau), a hair below the last samples:
  // 11 um (exp(-18) - exp(-20)) / 2 / 11 um ~ 5e-7 % "overshoot".
  EXPECT_NEAR(m.overshoot_pct, 0.0, 1e-6);
}

TEST(StepResponse, SecondOrderOvershootMatchesClosedForm) {
  // zeta = 0.5, wn = 2 pi 50 rad/s: overshoot exp(-zeta pi / sqrt(1 - zeta^2)) = 16.303 %,
  // peak at pi / (wn sqrt(1 - zeta^2)) = 11.547 ms. 2 % settling by the envelope bound is
  // ln(50 / sqrt(1 - zeta^2)) / (zeta wn) = 53 ms at most.
  const double zeta = 0.5, wn = 2 * std::numbers::pi * 50, wd = wn * std::sqrt(1 - zeta * zeta);
  std::vector<double> t, y;
  for (int k = 0; k <= 4000; ++k) {  // 0.4 s at 10 kHz
    const double tk = k * 1e-4;
    t.push_back(tk);
    y.push_back(kStep * (1 - std::exp(-zeta * wn * tk) *
                                 (std::cos(wd * tk) +
                                  zeta / std::sqrt(1 - zeta * zeta) * std::sin(wd * tk))));
  }
  const StepResponseMetrics m = step_response_metrics(t, y);
  EXPECT_NEAR(m.overshoot_pct,
              100 * std::exp(-zeta * std::numbers::pi / std::sqrt(1 - zeta * zeta)), 0.01);
  EXPECT_NEAR(m.overshoot_pct, 16.303, 0.01);
  EXPECT_NEAR(m.peak_time_s, std::numbers::pi / wd, 1e-4);
  EXPECT_GT(m.settling_time_pct_s, m.peak_time_s);
  EXPECT_LT(m.settling_time_pct_s, std::log(50 / std::sqrt(1 - zeta * zeta)) / (zeta * wn));
}

TEST(StepResponse, NoiseAndASpikeDoNotMoveTheSettlingTime) {
  Record r = first_order();
  test::GaussianNoise noise(3, 0.001);  // 1 nm rms, the XL-80's resolution
  for (double& v : r.y)
    v += noise();
  // A 0.5 um spike of two samples at 15 tau, outside both bands (+-0.22 um and +-10 nm).
  const auto spike = static_cast<std::size_t>(std::lround((kT0 + 15 * kTau) / kDt));
  r.y[spike] += 0.5;
  r.y[spike + 1] += 0.5;
  StepResponseOptions o;
  o.step_time_s = kT0;
  const StepResponseMetrics m = step_response_metrics(r.t, r.y, o);
  EXPECT_NEAR(m.settling_time_pct_s / kTau, std::log(50.0), 0.01);
  EXPECT_NEAR(m.rise_time_s / kTau, std::log(9.0), 0.01);
  // The absolute band is 10 nm against 1 nm noise: the crossing of a 1 nm/0.7 tau slope moves
  // by a few tenths of tau at most.
  EXPECT_NEAR(m.settling_time_abs_s / kTau, std::log(1100.0), 0.5);
  // Without the median the spike decides the settling time.
  o.median_window = 1;
  const StepResponseMetrics raw = step_response_metrics(r.t, r.y, o);
  EXPECT_NEAR(raw.settling_time_pct_s / kTau, 15.0 + 2 * kDt / kTau, 0.01);
}

TEST(StepResponse, NegativeStepAndUnsettledRecord) {
  Record r = first_order();
  for (double& v : r.y)
    v = 5.0 - v;  // 5 -> -6 um
  StepResponseOptions o;
  o.step_time_s = kT0;
  const StepResponseMetrics m = step_response_metrics(r.t, r.y, o);
  EXPECT_NEAR(m.step_um, -kStep, 1e-6);
  EXPECT_NEAR(m.rise_time_s / kTau, std::log(9.0), 1e-3);
  EXPECT_NEAR(m.settling_time_pct_s / kTau, std::log(50.0), 1e-3);
  // Told that the final value is 1 um further than it gets, the record never settles.
  o.final_um = -7.0;
  EXPECT_TRUE(std::isinf(step_response_metrics(r.t, r.y, o).settling_time_abs_s));
}

TEST(StepResponse, RunningMedianKeepsMonotoneDataAndRemovesSpikes) {
  const std::vector<double> y{0, 1, 2, 9, 4, 5, 6};
  const std::vector<double> f = running_median(y, 3);
  // Windows: [0], [0 1 2], [1 2 9], [2 9 4], [9 4 5], [4 5 6], [6].
  EXPECT_EQ(f, (std::vector<double>{0, 1, 2, 4, 5, 5, 6}));
  EXPECT_THROW(running_median(y, 4), MetricsError);
}

TEST(StepResponse, RejectsBadRecords) {
  const std::vector<double> t{0, 1, 1, 2}, y{0, 1, 1, 1};
  EXPECT_THROW(step_response_metrics(t, y), MetricsError);  // time not increasing
  const std::vector<double> t2{0, 1, 2, 3}, flat{1, 1, 1, 1};
  EXPECT_THROW(step_response_metrics(t2, flat), MetricsError);  // zero step
  StepResponseOptions late;
  late.step_time_s = 2.5;
  EXPECT_THROW(step_response_metrics(t2, y, late), MetricsError);  // 1 sample after the step
}

}  // namespace
}  // namespace piezoshift::experiments
