// The twin's open-loop fidelity targets, each against the paper (docs/twin.md, "Fidelity").
// Target 4 (the mechanism's mode) is in mechanics_test.cpp; the closed-loop targets 5 and 6 in
// tests/rig/loop_fidelity_test.cpp.
#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "open_loop.hpp"
#include "piezoshift/plant/twin.hpp"

namespace piezoshift::plant {
namespace {

using control::Vec3;

// Runs the twin open loop with the same DAQ volts on all three channels for the given time.
void hold(Twin& twin, double volts, double seconds) {
  const auto ticks = static_cast<long>(std::lround(seconds / twin.model().control_period_s));
  for (long k = 0; k < ticks; ++k)
    testing::hold_one_period(twin, Vec3{volts, volts, volts});
}

// Fidelity target 1, paper Section 4.1: 12.9 um (0.012931 mm) open loop at 150 V.
TEST(Fidelity1, OpenLoopTravelAtTenVoltsIsThePapers12Point9Microns) {
  Twin twin({}, {}, 1);
  hold(twin, 10.0, 1.5);
  EXPECT_NEAR(twin.truth().plate_z_um, 12.9, 0.3);
  EXPECT_NEAR(twin.truth().plate_z_um, 12.931, 0.01);  // the identification's own target
  hold(twin, 10.0, 0.5);
  // the interferometer's static reading over 1 s..2 s: with the identified per-leg stroke spread
  // the plate tilts, but the mean of P1..P3 stays at the identified travel (docs/twin.md)
  const InterferometerReading& r = twin.interferometer();
  ASSERT_EQ(r.static_count, 2u);
  EXPECT_NEAR((r.static_um[0] + r.static_um[1] + r.static_um[2]) / 3.0, 12.9, 0.3);
  // and each leg gives its own stack's share: the short stack (s = 0.875) about 11.1 um
  EXPECT_NEAR(twin.truth().leg_um[1] / twin.truth().leg_um[0], 0.875 / 1.011, 0.01);
}

// Fidelity target 2, Eq. 1: 16 um free, about 14.6 um on the mechanism, 0.1 s after 150 V.
TEST(Fidelity2, FreeStackGivesItsNominalStrokeAndOneLegOnItsMechanismFollowsEquation1) {
  TwinParams rigid;
  // the stiffest contact the ranges accept (twin_ranges.hpp): 1e6 N/um, rigid beside k_a = 70
  rigid.contact.stiffness_N_per_um = 1e6;
  rigid.piezo.free_stroke_scale = {1.0, 1.0, 1.0};  // the nominal stack of Table 1
  Twin twin({}, rigid, 1);
  // the amplifier slews 150 V in 5.8 ms; read 0.1 s after the voltage change is complete
  hold(twin, 10.0, 0.106);
  const TwinTruth& t = twin.truth();
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(t.amplifier_V[i], 150.0, 0.01);
    EXPECT_NEAR(t.free_elongation_um[i], 16.0, 0.05) << i;
    EXPECT_NEAR(t.leg_um[i], 16.0 * 70.0 / (70.0 + 6.7763), 0.05) << i;  // 14.59 um
    EXPECT_NEAR(t.leg_um[i], 14.6, 0.1) << i;
  }
  EXPECT_NEAR(twin.model().equation1_um, 14.588, 1e-3);
}

TEST(Fidelity2, WithTheIdentifiedContactALegDeliversLessThanEquation1) {
  TwinParams nominal;
  nominal.piezo.free_stroke_scale = {1.0, 1.0, 1.0};  // the nominal stack of Table 1
  Twin twin({}, nominal, 1);
  hold(twin, 10.0, 0.106);
  const TwinModel& m = twin.model();
  // Hertz, R = 5 mm: F0 identified from the 12.931 um travel; k_c = k_H(F0) (contact.hpp).
  // (The linear contact identified from the same travel was 41.86 N/um: the secant over the
  // stroke is that stiff; the linearization at the preload is softer.)
  EXPECT_TRUE(m.contact_hertz);
  EXPECT_NEAR(m.contact_preload_N, 146.8, 0.1);  // R F0 = 0.73 N m
  EXPECT_NEAR(m.contact_stiffness_N_per_um,
              hertz_stiffness_N_per_um(m.contact_preload_N, 0.005, m.contact_modulus_Pa), 1e-9);
  EXPECT_NEAR(m.contact_stiffness_N_per_um, 38.53, 0.01);
  const double km = m.mechanism_stiffness_N_per_um;
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(twin.truth().free_elongation_um[i], 16.0, 0.05);
    EXPECT_NEAR(twin.truth().leg_um[i], m.leg_static_um[i], 0.05);  // 12.71 um
    // the stack elongates more than the leg moves: the contact is compressed by Hertz's law
    const double x = twin.truth().leg_um[i];
    const double squeeze =
        hertz_deflection_um(m.contact_preload_N + km * x, 0.005, m.contact_modulus_Pa) -
        hertz_deflection_um(m.contact_preload_N, 0.005, m.contact_modulus_Pa);
    EXPECT_NEAR(twin.truth().stack_elongation_um[i], x + squeeze, 0.01);
  }
}

// Fidelity target 3: hysteresis of the full 0-150-0 V loop, 10 to 15 % of the range.
TEST(Fidelity3, OpenLoopHysteresisOverAFullCycleIsTenToFifteenPercent) {
  Twin twin({}, {}, 1);
  const int n = 2000;  // 2 s up, 2 s down
  std::vector<double> up_v, up_z;
  for (int k = 0; k <= n; ++k) {
    testing::hold_one_period(twin, Vec3{10.0 * k / n, 10.0 * k / n, 10.0 * k / n});
    up_v.push_back(twin.truth().amplifier_V[0]);
    up_z.push_back(twin.truth().plate_z_um);
  }
  const double range = up_z.back() - up_z.front();
  double gap = 0.0;
  for (int k = n; k >= 0; --k) {
    testing::hold_one_period(twin, Vec3{10.0 * k / n, 10.0 * k / n, 10.0 * k / n});
    const double v = twin.truth().amplifier_V[0];
    // the ascending branch at the same stack voltage (linear interpolation)
    const auto it = std::lower_bound(up_v.begin(), up_v.end(), v);
    if (it == up_v.begin() || it == up_v.end())
      continue;
    const std::size_t i = static_cast<std::size_t>(it - up_v.begin());
    const double f = (v - up_v[i - 1]) / (up_v[i] - up_v[i - 1]);
    const double z_up = up_z[i - 1] + f * (up_z[i] - up_z[i - 1]);
    gap = std::max(gap, twin.truth().plate_z_um - z_up);
  }
  const double h = gap / range;
  EXPECT_GE(h, 0.10);
  EXPECT_LE(h, 0.15);
  RecordProperty("hysteresis_fraction", std::to_string(h));
  // what it is: the rate-independent 12.5 % plus the creep of a 4 s cycle (about 1 % of range)
  EXPECT_NEAR(h, 0.135, 0.005);
}

// Fidelity target 3: creep of 1 to 2 % per decade of time after a step, open loop.
TEST(Fidelity3, OpenLoopCreepAfterAStepIsOneToTwoPercentPerDecade) {
  Twin twin({}, {}, 1);
  const double t_done = 0.006;  // the 150 V step is complete after 5.8 ms
  hold(twin, 10.0, t_done + 0.1);
  const double z01 = twin.truth().plate_z_um;
  hold(twin, 10.0, 0.9);
  const double z1 = twin.truth().plate_z_um;
  hold(twin, 10.0, 9.0);
  const double z10 = twin.truth().plate_z_um;
  const double first = (z1 - z01) / z01, second = (z10 - z1) / z01;
  EXPECT_GE(first, 0.01);
  EXPECT_LE(first, 0.02);
  EXPECT_GE(second, 0.01);
  EXPECT_LE(second, 0.02);
}

// Targets 5 (A by the paper's procedure) and 6 (one seed, one output) close the loop: they run
// through the loop every command ships, in tests/rig/loop_fidelity_test.cpp.

}  // namespace
}  // namespace piezoshift::plant
