// The improved controller's identification from records, against known truth: the channel model
// (hysteresis + creep) fitted back from a record the model itself produced, and the plate's mode
// from a damped cosine of known frequency (Prony's method is exact on one).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "piezoshift/calibration/hysteresis_identification.hpp"
#include "piezoshift/calibration/improved_calibration.hpp"
#include "piezoshift/calibration/mode_identification.hpp"

namespace piezoshift::calibration {
namespace {

constexpr double kT = 1e-3;

// A model on the fit's own grid (16 operators over 16 um, 11 creep terms 3 ms .. 300 s), with
// weights of mixed sizes and two operators at zero.
control::HysteresisCreepParams truth(double creep_gain, double threshold_phase = 0.5) {
  control::HysteresisCreepParams p;
  p.offset_um = 0.012;
  p.linear_weight = 0.52;
  p.operators = 16;
  for (std::size_t j = 0; j < p.operators; ++j) {
    p.threshold_um[j] = static_cast<double>(j) + threshold_phase;
    p.weight[j] = (j == 5 || j == 11) ? 0.0 : 0.01 + 0.004 * static_cast<double>(j % 7);
  }
  p.creep_terms = 11;
  for (std::size_t m = 0; m < p.creep_terms; ++m)
    p.creep_time_constant_s[m] = 0.003 * std::pow(10.0, static_cast<double>(m) / 2.0);
  p.creep_gain = creep_gain;
  return p;
}

struct Record {
  std::vector<double> u, y;
};

// The calibration's excitation through the model, the reading delayed by delay ticks.
Record record(const control::HysteresisCreepParams& p, std::size_t delay) {
  control::HysteresisCreepModel model;
  model.configure(p, kT);
  Record r;
  const auto n = static_cast<std::size_t>(std::llround(improved_excitation_duration_s() / kT));
  for (std::size_t k = 0; k < n; ++k)
    r.u.push_back(improved_excitation_um(static_cast<double>(k) * kT));
  for (std::size_t k = 0; k < n; ++k) {
    model.commit(k >= delay ? r.u[k - delay] : 0.0);
    r.y.push_back(model.output());
  }
  return r;
}

TEST(ChannelModelFit, RecoversAModelWithoutCreepExactly) {
  const control::HysteresisCreepParams p = truth(0.0);
  const Record r = record(p, 2);
  const HysteresisFit f = fit_hysteresis_creep(r.u, r.y, kT);
  EXPECT_EQ(f.delay_ticks, 2u);
  EXPECT_LT(f.rms_residual_um, 1e-9);
  EXPECT_NEAR(f.params.offset_um, p.offset_um, 1e-9);
  EXPECT_NEAR(f.params.linear_weight, p.linear_weight, 1e-9);
  for (std::size_t j = 0; j < p.operators; ++j)
    EXPECT_NEAR(f.params.weight[j], p.weight[j], 1e-9) << "operator " << j;
  EXPECT_NEAR(f.params.creep_gain, 0.0, 1e-9);
}

// With creep, each pass runs the creep regressor on the previous pass's hysteresis; iterated,
// the passes converge on the true model (the calibration's default). A single pass leaves 6.1 nm
// rms on this noise-free record, w0 0.1 % off and seven operators dropped: the next test.
TEST(ChannelModelFit, RecoversCreepByIteratingThePasses) {
  const control::HysteresisCreepParams p = truth(0.007);
  const Record r = record(p, 1);
  HysteresisFitOptions o;
  o.creep_start_candidates = 3;  // 3 ms (the truth's), 9.5 ms, 30 ms: the search must pick 3 ms
  const HysteresisFit f = fit_hysteresis_creep(r.u, r.y, kT, o);
  EXPECT_EQ(f.params.creep_time_constant_s[0], 0.003);
  EXPECT_EQ(f.delay_ticks, 1u);
  EXPECT_NEAR(f.params.creep_gain, p.creep_gain, 1e-6);
  EXPECT_NEAR(f.params.linear_weight, p.linear_weight, 1e-6);
  // The passes stop when the gain moves less than 1e-7; the weights are then within about 1e-6
  // (1.07e-6 seen on one), so 1e-5 for them.
  for (std::size_t j = 0; j < p.operators; ++j)
    EXPECT_NEAR(f.params.weight[j], p.weight[j], 1e-5) << "operator " << j;
  EXPECT_LT(f.rms_residual_um, 1e-5);
}

TEST(ChannelModelFit, OnePassLeavesTheCreepApproximate) {
  const control::HysteresisCreepParams p = truth(0.007);
  HysteresisFitOptions one;
  one.max_creep_passes = 1;
  const HysteresisFit f = fit_hysteresis_creep(record(p, 1).u, record(p, 1).y, kT, one);
  EXPECT_EQ(f.delay_ticks, 1u);
  EXPECT_NEAR(f.params.linear_weight, p.linear_weight, 0.002 * p.linear_weight);  // 0.1 % seen
  EXPECT_NEAR(f.params.creep_gain, p.creep_gain, 0.02 * p.creep_gain);            // 1.1 % seen
  EXPECT_GT(f.rms_residual_um, 1e-3);  // 6.1 nm seen: one pass is not exact
}

// The twin's stack has its play thresholds at odd microns of command (8 operators over 150 V =
// 16 um), which the centred grid (0.5, 1.5, ...) misses by half a spacing; the grid's phase is
// identified. On a model whose thresholds sit at whole microns, the centred grid alone is not
// exact and the search (1/2, then 1) is.
TEST(ChannelModelFit, IdentifiesTheThresholdGridsPhase) {
  control::HysteresisCreepParams p = truth(0.0, 1.0);
  p.weight[15] = 0.0;  // its threshold, 16 um, is beyond the excitation: never seen
  const Record r = record(p, 1);
  HysteresisFitOptions centred;
  centred.threshold_phase_candidates = 1;
  EXPECT_GT(fit_hysteresis_creep(r.u, r.y, kT, centred).rms_residual_um, 1e-4);
  const HysteresisFit f = fit_hysteresis_creep(r.u, r.y, kT);
  EXPECT_LT(f.rms_residual_um, 1e-9);
  EXPECT_NEAR(f.params.linear_weight, p.linear_weight, 1e-9);
  for (std::size_t j = 0; j < p.operators; ++j) {
    EXPECT_DOUBLE_EQ(f.params.threshold_um[j], p.threshold_um[j]) << "operator " << j;
    EXPECT_NEAR(f.params.weight[j], p.weight[j], 1e-9) << "operator " << j;
  }
}

TEST(ChannelModelFit, RefusesRecordsItCannotFit) {
  const Record r = record(truth(0.0), 0);
  std::vector<double> y = r.y;
  y.pop_back();
  EXPECT_THROW(fit_hysteresis_creep(r.u, y, kT), FitError);
  y = r.y;
  y[100] = std::nan("");
  EXPECT_THROW(fit_hysteresis_creep(r.u, y, kT), FitError);
  const std::vector<double> short_u(r.u.begin(), r.u.begin() + 50);
  EXPECT_THROW(fit_hysteresis_creep(short_u, short_u, kT), FitError);
  std::vector<double> falling = r.u;
  for (double& v : falling)
    v = -v;  // the gauge falls as the command rises: no slope to invert
  EXPECT_THROW(fit_hysteresis_creep(r.u, falling, kT), FitError);
}

// A ring at f on a constant, sampled at rate from the step on.
std::vector<double> ring(double f_Hz, double rate_Hz, double radius, std::size_t n) {
  std::vector<double> x;
  const double theta = 2.0 * std::numbers::pi * f_Hz / rate_Hz;
  for (std::size_t k = 0; k < n; ++k)
    x.push_back(5.3 - 0.3 * std::pow(radius, static_cast<double>(k)) *
                          std::cos(theta * static_cast<double>(k) + 0.4));
  return x;
}

TEST(PlateMode, PronyFindsADampedCosineExactlyAndFoldsIt) {
  // The twin's 1419 Hz piston mode seen at 10 kHz, then folded to 419 Hz at 1 kHz.
  const PlateModeEstimate fast = identify_plate_mode(ring(1419.0, 10000.0, 0.995, 300), 10000.0);
  EXPECT_NEAR(fast.mode_Hz, 1419.0, 1e-6);
  EXPECT_NEAR(fast.pole_radius, 0.995, 1e-9);
  const PlateModeEstimate slow = identify_plate_mode(ring(1419.0, 1000.0, 0.95, 30), 1000.0);
  EXPECT_NEAR(slow.mode_Hz, 419.0, 1e-6);
  EXPECT_NEAR(slow.theta_rad, 2.0 * std::numbers::pi * 0.419, 1e-9);
}

TEST(PlateMode, NoRingIsNoMode) {
  // Two real poles (0.9 and 0.5): a1 = 1.4, a2 = -0.45, a1 / (2 sqrt(-a2)) = 1.04 > 1.
  std::vector<double> x;
  for (int k = 0; k < 40; ++k)
    x.push_back(1.0 + 0.1 * std::pow(0.9, k) + 0.05 * std::pow(0.5, k));
  EXPECT_EQ(identify_plate_mode(x, 1000.0).mode_Hz, 0.0);
  EXPECT_EQ(identify_plate_mode(std::vector<double>(8, 1.0), 1000.0).mode_Hz, 0.0);
}

}  // namespace
}  // namespace piezoshift::calibration
