// The calibrations' cost estimates (calibration_cost.hpp) against what the simulation meter
// counts when they run, on the built-in twin and on one with a longer static window and a
// faster physics rate: the estimate a command refuses by must be the cost it would have had.
#include "piezoshift/calibration/calibration_cost.hpp"

#include <gtest/gtest.h>

#include "piezoshift/calibration/improved_calibration.hpp"
#include "piezoshift/experiments/paper_experiments.hpp"
#include "piezoshift/rig/simulation_meter.hpp"

namespace piezoshift::calibration {
namespace {

struct Metered {
  double simulated_s = 0.0;
  double physics_steps = 0.0;
};

template <typename Run>
Metered meter(Run run) {
  const rig::SimulationMeter a = rig::simulation_meter();
  run();
  const rig::SimulationMeter b = rig::simulation_meter();
  return {b.simulated_s - a.simulated_s, static_cast<double>(b.physics_steps - a.physics_steps)};
}

config::ProjectConfig slow_twin() {
  config::ProjectConfig c;
  c.twin.interferometer.static_average_s = 2.0;
  c.twin.physics_rate_Hz = 40000.0;
  return c;
}

// Within 2 %: the static measurements wait for the interferometer's next window, between one and
// two of them, so the window share is an average over the procedure's measurements.
void expect_estimate(const rig::ProcedureCost& cost, const config::ProjectConfig& c,
                     const Metered& m) {
  const rig::CostEstimate e = rig::estimate_cost(cost, c.twin);
  EXPECT_NEAR(e.simulated_s, m.simulated_s, 0.02 * m.simulated_s);
  EXPECT_NEAR(e.physics_steps, m.physics_steps, 0.02 * m.physics_steps);
}

TEST(CalibrationCost, StartUpCalibrationMatchesTheMeter) {
  for (const config::ProjectConfig& c : {config::ProjectConfig{}, slow_twin()}) {
    const CalibrationOptions o = CalibrationOptions::paper_gains_only();
    const Metered m = meter([&] { calibrate_with_travel(c, 1, o); });
    expect_estimate(calibration_cost(o, c.twin.daq.sample_time_s), c, m);
  }
}

TEST(CalibrationCost, DefaultCalibrationScoresTheWholeGridAndMatchesTheMeter) {
  const config::ProjectConfig c;
  const Metered m = meter([&] { calibrate_with_travel(c, 1); });
  expect_estimate(calibration_cost({}, c.twin.daq.sample_time_s), c, m);
}

TEST(CalibrationCost, ImprovedCalibrationWithItsTravelMatchesTheMeter) {
  for (const config::ProjectConfig& c : {config::ProjectConfig{}, slow_twin()}) {
    control::SemiClosedLoopParams base;
    base.sample_time_s = c.twin.daq.sample_time_s;
    const Metered m = meter([&] {
      const ImprovedCalibrationOutcome ic = calibrate_improved(c, base, 1);
      experiments::run_travel_range(c, ic.controller, 4, CalibrationOptions{}.travel);
    });
    expect_estimate(improved_calibration_cost(), c, m);
  }
}

TEST(CalibrationCost, ASettingThatWouldTakeHoursIsOverTheBudget) {
  config::ProjectConfig c;
  c.twin.interferometer.static_average_s = 1e6;  // about 28 h of `calibrate`
  const rig::CostEstimate e = rig::estimate_cost(
      calibration_cost(CalibrationOptions::paper_gains_only(), c.twin.daq.sample_time_s), c.twin);
  EXPECT_GT(e.simulated_s, 7.6e7);
  const std::string why = rig::procedure_budget_problem("calibrate", e, c.twin, 1e9, "--max-x");
  EXPECT_NE(why.find("static_average_s = 1e+06"), std::string::npos) << why;
  EXPECT_NE(why.find("--max-x"), std::string::npos) << why;
  EXPECT_EQ(rig::procedure_budget_problem("calibrate", e, c.twin, 1e15, "--max-x"), "");
}

}  // namespace
}  // namespace piezoshift::calibration
