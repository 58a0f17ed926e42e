// The sensor path's slow errors against their closed forms: the flicker generator's spectrum and
// window variance, the gauge creep against the makers' bound, the bridge excitation drift's rms,
// the interferometer's quantize-then-average, the lab's dead path (sgs.hpp, flicker.hpp,
// interferometer.hpp, lab_environment.hpp).
#include <cmath>
#include <complex>
#include <numbers>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "open_loop.hpp"
#include "piezoshift/plant/flicker.hpp"
#include "piezoshift/plant/interferometer.hpp"
#include "piezoshift/plant/lab_environment.hpp"
#include "piezoshift/plant/random.hpp"
#include "piezoshift/plant/twin.hpp"
#include "piezoshift/plant/twin_model.hpp"

namespace piezoshift::plant {
namespace {

// Welch's averaged periodogram (Hann window, one-sided) at bin k of segments of length n.
double welch_psd(const std::vector<double>& x, std::size_t n, std::size_t k, double dt) {
  const std::size_t segments = x.size() / n;
  double w2 = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double w = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(i) /
                                          static_cast<double>(n));
    w2 += w * w;
  }
  double sum = 0.0;
  for (std::size_t s = 0; s < segments; ++s) {
    std::complex<double> acc{0.0, 0.0};
    double mean = 0.0;
    for (std::size_t i = 0; i < n; ++i)
      mean += x[s * n + i];
    mean /= static_cast<double>(n);
    // the twiddle factor by rotation (its rounding stays far below the estimate's spread)
    const std::complex<double> rot =
        std::polar(1.0, -2.0 * std::numbers::pi * static_cast<double>(k) / static_cast<double>(n));
    std::complex<double> tw{1.0, 0.0};
    for (std::size_t i = 0; i < n; ++i) {
      const double w = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(i) /
                                            static_cast<double>(n));
      acc += w * (x[s * n + i] - mean) * tw;
      tw *= rot;
    }
    sum += std::norm(acc);
  }
  return 2.0 * dt * sum / w2 / static_cast<double>(segments);
}

TEST(Flicker, ModelSpectrumIsOneOverFBetweenItsCorners) {
  const double a = 2.0e-3;  // units^2 / Hz at 1 Hz
  const FlickerNoise f(a, 0.01, 1.0e4, 1, 1e-3);
  EXPECT_EQ(f.terms(), 7u);
  // Integrating the Lorentzians over log tau gives A / f; one term per decade ripples by a few %.
  for (const double hz : {1e-3, 3e-3, 1e-2, 0.1, 0.3, 1.0})
    EXPECT_NEAR(f.psd(hz) * hz / a, 1.0, 0.06) << hz;
}

TEST(Flicker, SimulatedSpectrumFallsAsOneOverFOverTwoDecades) {
  // Unit update period, 1/f from 1.6e-8 to 0.16 Hz; measured between 1e-4 and 1e-2 Hz.
  const double a = 1.0;
  const FlickerNoise f(a, 1.0, 1.0e7, 1, 1.0);
  Rng rng(3);
  FlickerState s{};
  f.start(s, rng);
  const std::size_t n = 1u << 16, segments = 24;
  std::vector<double> x(n * segments);
  for (std::size_t t = 0; t < x.size(); ++t)
    x[t] = f.update(s, t + 1, rng);
  // Least-squares slope of log PSD against log f, each point the mean of 5 neighbouring bins.
  std::vector<double> lf, lp;
  for (double hz = 1e-4; hz <= 1.001e-2; hz *= std::sqrt(10.0)) {
    const auto k0 = static_cast<std::size_t>(std::lround(hz * static_cast<double>(n)));
    double p = 0.0;
    for (std::size_t k = k0 - 2; k <= k0 + 2; ++k)
      p += welch_psd(x, n, k, 1.0);
    p /= 5.0;
    EXPECT_NEAR(p / f.psd(hz), 1.0, 0.25) << hz;  // the closed form, within the estimate's spread
    lf.push_back(std::log10(hz));
    lp.push_back(std::log10(p));
  }
  double mx = 0.0, my = 0.0;
  for (std::size_t i = 0; i < lf.size(); ++i) {
    mx += lf[i];
    my += lp[i];
  }
  mx /= static_cast<double>(lf.size());
  my /= static_cast<double>(lf.size());
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t i = 0; i < lf.size(); ++i) {
    sxy += (lf[i] - mx) * (lp[i] - my);
    sxx += (lf[i] - mx) * (lf[i] - mx);
  }
  EXPECT_NEAR(sxy / sxx, -1.0, 0.1);
}

TEST(Flicker, SampleVarianceOverAWindowIsTheClosedForm) {
  // 1 s to 1e4 s, updated every 0.1 s; 300 windows of 500 s.
  const double a = flicker_psd_for_window_rms(2.0, 500.0, 1.0, 1.0e4, 1);
  const FlickerNoise f(a, 1.0, 1.0e4, 1, 0.1);
  EXPECT_NEAR(f.window_variance(500.0), 4.0, 1e-12);
  Rng rng(5);
  double var_sum = 0.0;
  const int windows = 300;
  for (int w = 0; w < windows; ++w) {
    FlickerState s{};
    f.start(s, rng);
    double m = 0.0, m2 = 0.0;
    const int n = 5000;
    for (int t = 1; t <= n; ++t) {
      const double x = f.update(s, static_cast<std::uint64_t>(t), rng);
      m += x;
      m2 += x * x;
    }
    m /= n;
    var_sum += (m2 - n * m * m) / (n - 1);
  }
  EXPECT_NEAR(std::sqrt(var_sum / windows), 2.0, 0.15);
}

TEST(GaugeCreep, AStepCreepsByTheMakersBoundInTwentyMinutes) {
  const TwinModel m = make_twin_model({}, {});
  // 0.02 % of the step after 1200 s, exactly in the continuous step response ...
  EXPECT_NEAR(m.gauge_creep.step_response(1200.0), 2e-4, 1e-12);
  // ... and in the discrete chain the twin runs at 1 kHz, driven by 10 um of elongation.
  CreepState c{};
  double d = 0.0;
  for (int k = 0; k < 1200000; ++k)
    d = m.gauge_creep.update(c, 10.0);
  EXPECT_NEAR(d, 10.0 * 2e-4, 10.0 * 2e-4 * 0.01);  // 2 nm, the bound's 0.02 % of 10 um
  // log creep: half of it by ~1 s (5 of the chain's 10 decades)
  EXPECT_NEAR(m.gauge_creep.step_response(1.0) / 2e-4, 0.5, 0.1);
}

TEST(ExcitationDrift, RmsOverTheRepeatabilityRunIsTheIdentified258Ppm) {
  const TwinModel m = make_twin_model({}, {});
  const FlickerNoise& f = m.sgs_excitation_drift;
  EXPECT_NEAR(std::sqrt(f.window_variance(690.0)) * 1e6, 258.0, 1e-6);
  // b = 258 ppm: sqrt(a^2 + (5 b)^2) = 2 nm and sqrt(a^2 + (10 b)^2) = 3 nm (Section 4.3)
  const double b = std::sqrt(5.0 / 75.0), a0 = std::sqrt(4.0 - 25.0 * b * b);
  EXPECT_NEAR(b * 1e3, 258.2, 0.1);
  EXPECT_NEAR(a0, 1.528, 0.001);
  // Simulated at the twin's 1 kHz, sampled once per second (one reading per second), 60 runs.
  Rng rng(8);
  double var_sum = 0.0;
  const int runs = 60;
  for (int r = 0; r < runs; ++r) {
    FlickerState s{};
    f.start(s, rng);
    double s1 = 0.0, s2 = 0.0;
    int n = 0;
    for (std::uint64_t t = 1; t <= 690000; ++t) {
      const double x = f.update(s, t, rng);
      if (t % 1000 == 0) {
        s1 += x;
        s2 += x * x;
        ++n;
      }
    }
    var_sum += (s2 - s1 * s1 / n) / (n - 1);
  }
  EXPECT_NEAR(std::sqrt(var_sum / runs) * 1e6, 258.0, 30.0);
}

TEST(Interferometer, StaticModeAveragesQuantizedSamples) {
  // 600 samples at 0.45 nm (each counts 0) and 400 at 0.9 nm (each counts 1): the counts average
  // to 0.4 nm and read 0 nm; the positions would average to 0.63 nm and read 1 nm.
  double sum = 0.0;
  for (int i = 0; i < 1000; ++i)
    sum += interferometer_quantize(i < 600 ? 0.45 : 0.9, 1.0);
  EXPECT_EQ(sum, 400.0);
  EXPECT_EQ(interferometer_static_reading(sum, 1000.0, 1.0), 0.0);
  EXPECT_EQ(interferometer_quantize((600 * 0.45 + 400 * 0.9) / 1000.0, 1.0), 1.0);
  // With 1 nm of noise the counts dither: the mean of many is unbiased to well below a count.
  Rng rng(2);
  double q = 0.0;
  for (int i = 0; i < 100000; ++i)
    q += interferometer_quantize(0.3 + rng.normal(), 1.0);
  EXPECT_NEAR(q / 100000.0, 0.3, 0.01);
}

TEST(Lab, DeadPathDriftIsItsLengthTimesDnDtTimesTheAirsChange) {
  LabParams p;
  p.metrology_loop_cte_per_K = 0.0;  // the dead path alone
  LabEnvironment lab(p, 1e-3);
  Rng rng(4);
  LabState s{};
  lab.start(s, rng);
  const double air0 = s.air_K;
  for (int k = 0; k < 200000; ++k)
    lab.update(s, rng);
  const double expected_um = 1e6 * p.dead_path_m * p.air_index_per_K * (s.air_K - air0);
  EXPECT_NEAR(lab.drift_um(s), expected_um, 1e-15);
  EXPECT_NE(s.air_K, air0);
  EXPECT_NEAR(-0.93e-6 * 0.02 * 1e9, -18.6, 1e-9);  // nm per K of air
}

TEST(Lab, AirAndStructureHaveTheirStationaryVariances) {
  // Updated every 10 s to cover many correlation times; var(y) = sigma^2 tau_a / (tau_a + tau_s).
  const LabParams p;
  LabEnvironment lab(p, 10.0);
  Rng rng(6);
  LabState s{};
  lab.start(s, rng);
  double ax = 0.0, ay = 0.0;
  const int n = 2000000;
  for (int k = 0; k < n; ++k) {
    lab.update(s, rng);
    ax += s.air_K * s.air_K;
    ay += s.structure_K * s.structure_K;
  }
  EXPECT_NEAR(std::sqrt(ax / n), 0.03, 0.0015);
  // The discrete lag (forward step of 10 s on 1800 s) adds < 0.3 %.
  EXPECT_NEAR(std::sqrt(ay / n), 0.03 * std::sqrt(600.0 / 2400.0), 0.001);
}

}  // namespace
}  // namespace piezoshift::plant

namespace piezoshift::plant {
namespace {

TEST(HertzContact, DeflectionAndItsLinearizationAreTheClosedForms) {
  const double e = hertz_contact_modulus_Pa(2.1e11, 0.28);  // Table 2
  EXPECT_NEAR(e, 2.1e11 / (2.0 * (1.0 - 0.28 * 0.28)), 1.0);
  EXPECT_NEAR(e / 1e9, 113.9, 0.1);
  const double r = 0.005, f = 150.0;
  // d = (9 F^2 / (16 E*^2 R))^(1/3)
  EXPECT_NEAR(hertz_deflection_um(f, r, e), 1e6 * std::cbrt(9.0 * f * f / (16.0 * e * e * r)),
              1e-12);
  // k = dF/dd = (6 E*^2 R F)^(1/3) = 3 F / (2 d): against a central difference
  const double h = 1e-3;
  const double dd = hertz_deflection_um(f + h, r, e) - hertz_deflection_um(f - h, r, e);
  EXPECT_NEAR(hertz_stiffness_N_per_um(f, r, e), 2.0 * h / dd, 1e-6);
  EXPECT_NEAR(hertz_stiffness_N_per_um(f, r, e), 1.5 * f / hertz_deflection_um(f, r, e), 1e-9);
  // the residual beyond the linearization: zero with zero slope at the preload, <= 0 elsewhere
  const HertzResidual res = make_hertz_residual(f, r, e);
  EXPECT_NEAR(res(0.0), 0.0, 1e-12);
  EXPECT_NEAR((res(h) - res(-h)) / (2.0 * h), 0.0, 1e-8);
  for (const double df : {-100.0, -20.0, 20.0, 90.0})
    EXPECT_LT(res(df), 0.0) << df;
  EXPECT_NEAR(res(90.0),
              hertz_deflection_um(240.0, r, e) - hertz_deflection_um(150.0, r, e) -
                  90.0 / hertz_stiffness_N_per_um(150.0, r, e),
              1e-12);
}

TEST(HertzContact, PreloadIdentificationInvertsTheLegStatics) {
  const double e = hertz_contact_modulus_Pa(2.1e11, 0.28), ka = 70.0, km = 6.7763;
  const double f0 = identify_hertz_preload_N(12.931, 16.276, ka, km, 0.005, e);
  EXPECT_NEAR(hertz_static_leg_um(16.276, ka, km, f0, 0.005, e), 12.931, 1e-9);
  // a stroke the rigid contact cannot deliver has no preload
  EXPECT_THROW(identify_hertz_preload_N(14.7, 16.0, ka, km, 0.005, e), std::invalid_argument);
}

TEST(HertzContact, TwinStaticsAreTheExactHertzSolution) {
  // Open loop, held: the residual lagged by one period converges to the exact statics.
  Twin twin({}, {}, 1);
  const TwinModel& m = twin.model();
  for (const double volts : {10.0, 4.0}) {
    for (int k = 0; k < 500; ++k)
      testing::hold_one_period(twin, {volts, volts, volts});
    for (std::size_t i = 0; i < 3; ++i) {
      const double exact =
          hertz_static_leg_um(twin.truth().free_elongation_um[i], m.actuator_stiffness_N_per_um,
                              m.mechanism_stiffness_N_per_um, m.contact_preload_N,
                              m.params.contact.ball_radius_m, m.contact_modulus_Pa);
      // creep still moves x_free by ~0.1 nm per period after 0.5 s
      EXPECT_NEAR(twin.truth().leg_um[i], exact, 2e-4) << volts << " V, leg " << i;
    }
  }
}

}  // namespace
}  // namespace piezoshift::plant
