#include "piezoshift/plant/simulation_cost.hpp"

#include <cmath>

#include <fmt/core.h>

namespace piezoshift::plant {

SimulationCost estimate_simulation_cost(const TwinParams& twin, double duration_s) {
  const double per_tick =
      std::fmax(1.0, std::ceil(twin.physics_rate_Hz * twin.daq.sample_time_s - 1e-9));
  SimulationCost c;
  c.control_ticks = duration_s / twin.daq.sample_time_s;
  c.physics_steps = c.control_ticks * per_tick;
  return c;
}

namespace {
std::string count(double n) {
  return std::isfinite(n) ? fmt::format("{:.3g}", n) : std::string("more than 1e+308");
}
}  // namespace

std::string simulation_budget_problem(const SimulationCost& cost, double budget_physics_steps,
                                      std::string_view raise_option) {
  if (cost.physics_steps <= budget_physics_steps)
    return {};
  return fmt::format(
      "the simulation needs an estimated {} physics steps ({} control ticks), above the budget "
      "of {:.3g} (some 60 to 100 ns each); shorten it, or raise the budget with {}",
      count(cost.physics_steps), count(cost.control_ticks), budget_physics_steps, raise_option);
}

}  // namespace piezoshift::plant
