// The twin as a whole: its DAQ view, sensors, faults and the checks on its parameters (closed
// loops go through the shipping loop: tests/rig/loop_fidelity_test.cpp).
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "open_loop.hpp"
#include "piezoshift/control/vec3.hpp"
#include "piezoshift/plant/random.hpp"
#include "piezoshift/plant/twin.hpp"

namespace piezoshift::plant {
namespace {

using control::Vec3;

void hold(Twin& twin, const Vec3& volts, double seconds) {
  const auto ticks = static_cast<long>(std::lround(seconds / twin.model().control_period_s));
  for (long k = 0; k < ticks; ++k)
    testing::hold_one_period(twin, volts);
}

double mean(const std::vector<double>& v) {
  double s = 0.0;
  for (const double x : v)
    s += x;
  return s / static_cast<double>(v.size());
}

double stddev(const std::vector<double>& v) {
  const double m = mean(v);
  double s = 0.0;
  for (const double x : v)
    s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1));
}

TEST(Rng, NormalDeviatesHaveTheNormalsMomentsAndTailsAndAreReproducible) {
  Rng a(9), b(9);
  std::vector<double> v;
  int beyond_2 = 0, beyond_3_5 = 0;
  const int n = 1000000;
  for (int i = 0; i < n; ++i) {
    const double x = a.normal();
    ASSERT_EQ(x, b.normal());
    v.push_back(x);
    beyond_2 += std::fabs(x) > 2.0 ? 1 : 0;
    beyond_3_5 += std::fabs(x) > 3.5 ? 1 : 0;  // the ziggurat's tail starts at 3.4426
  }
  EXPECT_NEAR(mean(v), 0.0, 0.005);
  EXPECT_NEAR(stddev(v), 1.0, 0.005);
  EXPECT_NEAR(beyond_2, 0.0455003 * n, 5 * std::sqrt(0.0455 * n));       // 45500 +- 1070
  EXPECT_NEAR(beyond_3_5, 4.6525e-4 * n, 5 * std::sqrt(4.6525e-4 * n));  // 465 +- 108
}

TEST(Twin, WriteReportsClampedAndInvalidOutputsAndKeepsTheLastGoodValue) {
  Twin twin({}, {}, 1);
  EXPECT_EQ(twin.write_ao({1.0, 2.0, 3.0}), AoStatus::kOk);
  EXPECT_EQ(twin.write_ao({12.0, 2.0, 3.0}), AoStatus::kClamped);
  EXPECT_EQ(twin.write_ao({NAN, 2.0, 3.0}), AoStatus::kInvalid);
  twin.advance();
  const double q = 20.0 / 65536.0;
  EXPECT_NEAR(twin.truth().ao_V[0], 10.0 - q, 1e-12);  // the clamped value, kept
  EXPECT_NEAR(twin.truth().ao_V[1], 2.0, q / 2);
}

TEST(Twin, StrainGaugeReadsTheIdentifiedGainTimesTheLegAndItsNoiseIsStated) {
  Twin twin({}, {}, 1);
  hold(twin, {5.0, 5.0, 5.0}, 1.0);
  const TwinModel& m = twin.model();
  std::vector<std::vector<double>> ai(3);
  for (int k = 0; k < 2000; ++k) {
    testing::hold_one_period(twin, {5.0, 5.0, 5.0});
    for (std::size_t i = 0; i < 3; ++i)
      ai[i].push_back(twin.read_ai()[i]);
  }
  const double sigma_V = std::hypot(1.5e-3 / 1.6, 280e-6);  // 0.98 mV
  for (std::size_t i = 0; i < 3; ++i) {
    const double reading_um = mean(ai[i]) * 1.6;
    const double leg = twin.truth().leg_um[i];
    // S_i = g_i x_i (paper's A), up to the conditioner's 0.1 % bow (16 nm at most) and creep
    EXPECT_NEAR(reading_um, m.geometry.sgs_gain[i] * leg, 0.03) << i;
    // noise from successive differences (the reading also creeps slowly): sigma = sd(diff) / sqrt 2
    std::vector<double> diff;
    for (std::size_t k = 1; k < ai[i].size(); ++k)
      diff.push_back(ai[i][k] - ai[i][k - 1]);
    EXPECT_NEAR(stddev(diff) / std::sqrt(2.0), sigma_V, 0.1 * sigma_V) << i;
  }
}

TEST(Twin, InterferometerReadsInWholeNanometresAndAveragesEachSecond) {
  Twin twin({}, {}, 1);
  hold(twin, {3.0, 3.0, 3.0}, 3.0);
  const InterferometerReading& r = twin.interferometer();
  EXPECT_EQ(r.static_count, 3u);
  EXPECT_NEAR(r.static_time_s, 3.0, 1e-9);
  for (std::size_t j = 0; j < 3; ++j) {
    EXPECT_NEAR(r.dynamic_um[j] * 1e3, std::round(r.dynamic_um[j] * 1e3), 1e-6);
    EXPECT_NEAR(r.static_um[j] * 1e3, std::round(r.static_um[j] * 1e3), 1e-6);
    EXPECT_NEAR(r.dynamic_um[j], twin.truth().points_um[j], 0.006);  // 1 nm noise, drift
  }
}

// The period's average of the plate, what a camera exposure of one period integrates: while the
// plate moves it lies strictly between the period's extremes; with one physics step per period it
// is the end-of-period position itself.
TEST(Twin, PeriodAverageOfThePlateLiesBetweenItsExtremesAndIsExactWithOneStepPerPeriod) {
  Twin twin({}, {}, 1);
  hold(twin, {0.0, 0.0, 0.0}, 0.01);
  int strictly_inside = 0;
  for (int k = 0; k < 5; ++k) {
    testing::hold_one_period(twin, {5.0, 5.0, 5.0});
    const TwinTruth& t = twin.truth();
    EXPECT_LE(t.period_min_mean_points_um, t.period_avg_mean_points_um);
    EXPECT_LE(t.period_avg_mean_points_um, t.period_max_mean_points_um);
    if (t.period_avg_mean_points_um > t.period_min_mean_points_um + 1e-6 &&
        t.period_avg_mean_points_um < t.period_max_mean_points_um - 1e-6)
      ++strictly_inside;
  }
  EXPECT_EQ(strictly_inside, 5);

  TwinParams one_step;
  one_step.physics_rate_Hz = 1.0 / one_step.daq.sample_time_s;
  Twin coarse({}, one_step, 1);
  for (int k = 0; k < 20; ++k) {
    testing::hold_one_period(coarse, {5.0, 5.0, 5.0});
    const TwinTruth& t = coarse.truth();
    const double points = (t.points_um[0] + t.points_um[1] + t.points_um[2]) / 3.0;
    EXPECT_NEAR(t.period_avg_mean_points_um, points, 1e-12);
    EXPECT_DOUBLE_EQ(t.period_avg_mean_points_um, t.period_max_mean_points_um);
  }
}

TEST(Faults, AmplifierFailureDischargesTheStackAndOpenGaugeReadsFullScale) {
  Twin twin({}, {}, 1);
  hold(twin, {5.0, 5.0, 5.0}, 0.1);
  ChannelFault amp_off;
  amp_off.amplifier_failed = true;
  twin.set_fault(0, amp_off);
  ChannelFault open;
  open.sgs_open = true;
  twin.set_fault(1, open);
  ChannelFault nan;
  nan.adc_nan = true;
  twin.set_fault(2, nan);
  hold(twin, {5.0, 5.0, 5.0}, 0.05);
  EXPECT_EQ(twin.truth().amplifier_V[0], 0.0);
  EXPECT_NEAR(twin.read_ai()[1], 10.0 - 20.0 / 65536.0, 1e-12);  // the ADC's end code
  EXPECT_TRUE(std::isnan(twin.read_ai()[2]));
  twin.set_fault(0, {});
  twin.set_fault(1, {});
  twin.set_fault(2, {});
  hold(twin, {5.0, 5.0, 5.0}, 0.05);
  EXPECT_NEAR(twin.truth().amplifier_V[0], 75.0, 1e-6);
  EXPECT_FALSE(std::isnan(twin.read_ai()[2]));
}

TEST(Faults, ACrackedStackLosesStrokeOnItsOwnLeg) {
  Twin healthy({}, {}, 1), cracked({}, {}, 1);
  ChannelFault crack;
  crack.stack_stiffness_scale = 0.5;
  cracked.set_fault(1, crack);
  hold(healthy, {8.0, 8.0, 8.0}, 0.5);
  hold(cracked, {8.0, 8.0, 8.0}, 0.5);
  const TwinModel& m = healthy.model();
  const double ks = 1.0 / (1.0 / 35.0 + 1.0 / m.contact_stiffness_N_per_um);  // k_a halved
  const double ratio = (ks / (ks + m.mechanism_stiffness_N_per_um)) /
                       (m.series_stiffness_N_per_um /
                        (m.series_stiffness_N_per_um + m.mechanism_stiffness_N_per_um));
  EXPECT_NEAR(cracked.truth().leg_um[1] / healthy.truth().leg_um[1], ratio, 1e-3);
  EXPECT_NEAR(cracked.truth().leg_um[0], healthy.truth().leg_um[0], 1e-5);  // plate coupling
}

TEST(Params, ProblemsNameTheParameter) {
  const design::DesignInputs d;
  EXPECT_EQ(twin_params_problem(d, {}), "");
  TwinParams p;
  p.physics_rate_Hz = 15500.0;
  EXPECT_NE(twin_params_problem(d, p).find("twin.physics_rate_Hz"), std::string::npos);
  p = {};
  p.plate.radius_m = 0.05;
  EXPECT_NE(twin_params_problem(d, p).find("twin.plate.radius_m"), std::string::npos);
  p = {};
  p.contact.open_loop_travel_um = 15.0;
  EXPECT_NE(twin_params_problem(d, p).find("open-loop travel"), std::string::npos);
  p = {};
  p.geometry.transmission_matrix[0] = {-1.0, 0.2, 0.1};
  EXPECT_NE(twin_params_problem(d, p).find("twin.geometry"), std::string::npos);
  EXPECT_THROW(Twin(d, p, 1), std::invalid_argument);
}

}  // namespace
}  // namespace piezoshift::plant
