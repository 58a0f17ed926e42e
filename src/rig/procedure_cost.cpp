#include "piezoshift/rig/procedure_cost.hpp"

#include <cmath>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/plant/simulation_cost.hpp"

namespace piezoshift::rig {

CostEstimate estimate_cost(const ProcedureCost& cost, const plant::TwinParams& twin,
                           double repeats) {
  CostEstimate e;
  e.simulated_s = repeats * (cost.fixed_s + cost.window_s * twin.interferometer.static_average_s);
  e.physics_steps = plant::estimate_simulation_cost(twin, e.simulated_s).physics_steps;
  return e;
}

std::string procedure_budget_problem(std::string_view procedure, const CostEstimate& estimate,
                                     const plant::TwinParams& twin, double budget_physics_steps,
                                     std::string_view raise_option) {
  if (estimate.physics_steps <= budget_physics_steps)
    return {};
  return fmt::format(
      "{} needs an estimated {:.3g} physics steps ({:.3g} s of simulated time with "
      "[twin.interferometer] static_average_s = {:g} s, physics_rate_Hz = {:g} and "
      "[twin.daq] sample_time_s = {:g} s), above the budget of {:.3g} (some 60 to 100 ns each); "
      "change those settings, or raise the budget with {}",
      procedure, estimate.physics_steps, estimate.simulated_s, twin.interferometer.static_average_s,
      twin.physics_rate_Hz, twin.daq.sample_time_s, budget_physics_steps, raise_option);
}

void check_procedure_budget(std::string_view procedure, const ProcedureCost& cost,
                            const plant::TwinParams& twin, double budget_physics_steps,
                            std::string_view raise_option, double repeats) {
  const CostEstimate e = estimate_cost(cost, twin, repeats);
  if (const std::string why =
          procedure_budget_problem(procedure, e, twin, budget_physics_steps, raise_option);
      !why.empty())
    throw core::InputError(why);
}

}  // namespace piezoshift::rig
