// The stack's rate-independent hysteresis and its creep chain.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "piezoshift/plant/creep.hpp"
#include "piezoshift/plant/hysteresis.hpp"

namespace piezoshift::plant {
namespace {

struct Loop {
  double range = 0.0;  // y at the top, from 0 at the bottom
  double gap = 0.0;    // largest descending - ascending at one voltage
};

Loop major_loop(const PrandtlIshlinskii& pi, int points) {
  PlayState u{};
  std::vector<double> up(static_cast<std::size_t>(points) + 1);
  for (int k = 0; k <= points; ++k)
    up[static_cast<std::size_t>(k)] = pi.update(u, 150.0 * k / points);
  Loop loop;
  loop.range = up.back() - up.front();
  for (int k = points; k >= 0; --k) {
    const double down = pi.update(u, 150.0 * k / points);
    loop.gap = std::max(loop.gap, down - up[static_cast<std::size_t>(k)]);
  }
  return loop;
}

TEST(Hysteresis, MajorLoopHasTheStatedWidthAndUnitRange) {
  for (const double h : {0.10, 0.125, 0.15}) {
    const PrandtlIshlinskii pi(HysteresisParams{h, 8}, 150.0);
    const Loop loop = major_loop(pi, 1600);
    EXPECT_NEAR(loop.range, 1.0, 1e-12) << h;
    EXPECT_NEAR(loop.gap / loop.range, h, 1e-12) << h;
  }
}

TEST(Hysteresis, SlopesAreThreeQuartersAfterAReversalAndFiveQuartersAtTheTop) {
  const PrandtlIshlinskii pi(HysteresisParams{0.125, 8}, 150.0);
  EXPECT_NEAR(pi.linear_weight(), 0.75, 1e-12);                             // w0
  EXPECT_NEAR(pi.linear_weight() + 8 * pi.operator_weight(), 1.25, 1e-12);  // w0 + W
}

TEST(Hysteresis, LoopClosesAndStartsAtZeroOnTheMajorLoop) {
  const PrandtlIshlinskii pi(HysteresisParams{0.125, 8}, 150.0);
  PlayState u{};
  EXPECT_EQ(pi.update(u, 0.0), 0.0);
  for (int cycle = 0; cycle < 3; ++cycle) {
    for (int k = 0; k <= 300; ++k)
      pi.update(u, 150.0 * k / 300);
    double y = 0.0;
    for (int k = 300; k >= 0; --k)
      y = pi.update(u, 150.0 * k / 300);
    EXPECT_NEAR(y, 0.0, 1e-12);
  }
}

TEST(Hysteresis, RejectsImpossibleParameters) {
  EXPECT_THROW(PrandtlIshlinskii(HysteresisParams{0.5, 8}, 150.0), std::invalid_argument);
  EXPECT_THROW(PrandtlIshlinskii(HysteresisParams{0.1, 0}, 150.0), std::invalid_argument);
  EXPECT_THROW(PrandtlIshlinskii(HysteresisParams{0.1, 33}, 150.0), std::invalid_argument);
  EXPECT_THROW(PrandtlIshlinskii(HysteresisParams{0.1, 8}, 0.0), std::invalid_argument);
}

// The twin evaluates monotone runs with PlaySweep; it must agree with update() everywhere.
TEST(Hysteresis, SweepAgreesWithTheOperatorUpdateOnRandomMonotoneRuns) {
  const PrandtlIshlinskii pi(HysteresisParams{0.125, 8}, 150.0);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> volts(0.0, 150.0), step(0.0, 4.0);
  PlayState a{}, b{};
  double v = 0.0;
  for (int run = 0; run < 400; ++run) {
    const double target = volts(rng);
    const bool rising = target > v;
    PlaySweep sweep(pi, b, rising);
    for (int k = 0; k < 20; ++k) {
      v = rising ? std::min(target, v + step(rng)) : std::max(target, v - step(rng));
      const double ya = pi.update(a, v);
      const double yb = sweep.at(v);
      ASSERT_NEAR(ya, yb, 1e-12) << "run " << run << " step " << k;
    }
    sweep.commit(b);
    for (std::size_t j = 0; j < pi.operators(); ++j)
      ASSERT_NEAR(a[j], b[j], 1e-15);
  }
}

// An input beyond every breakpoint (infinite, as a denormal output_max_V made it) used to
// pass the last breakpoint's sentinel forever; the sweep stops after the last operator.
TEST(Hysteresis, SweepTerminatesOnAnInfiniteInput) {
  const PrandtlIshlinskii pi(HysteresisParams{0.125, 8}, 150.0);
  PlayState u{};
  PlaySweep up(pi, u, true);
  EXPECT_EQ(up.at(std::numeric_limits<double>::infinity()),
            std::numeric_limits<double>::infinity());
  PlaySweep down(pi, u, false);
  EXPECT_EQ(down.at(-std::numeric_limits<double>::infinity()),
            -std::numeric_limits<double>::infinity());
}

TEST(Creep, SlopeIsTheStatedFractionPerDecadeInTheMiddleOfTheChain) {
  const CreepChain chain(CreepParams{0.015, 0.01, 1000.0, 2}, 1e-3);
  EXPECT_EQ(chain.terms(), 11u);  // 0.01 s to 1000 s, two per decade
  for (const double t : {0.1, 1.0, 10.0}) {
    const double per_decade = chain.step_response(10.0 * t) - chain.step_response(t);
    EXPECT_NEAR(per_decade, 0.015, 0.0015) << t;
  }
}

TEST(Creep, DiscreteUpdateMatchesTheContinuousStepResponse) {
  const CreepChain chain(CreepParams{0.015, 0.01, 1000.0, 2}, 1e-3);
  CreepState c{};
  double out = 0.0;
  for (int k = 1; k <= 5000; ++k) {
    out = chain.update(c, 1.0);
    if (k == 100 || k == 1000 || k == 5000) {
      EXPECT_NEAR(out, chain.step_response(k * 1e-3), 1e-12) << k;  // exact for a held input
    }
  }
}

}  // namespace
}  // namespace piezoshift::plant
