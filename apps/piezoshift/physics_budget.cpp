#include "physics_budget.hpp"

#include <string>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"

namespace piezoshift::app {

void add_physics_budget_option(CLI::App* cmd, double& budget) {
  cmd->add_option("--max-physics-steps", budget,
                  "refuse a simulation estimated above this many physics steps (default 1e9, "
                  "about a minute of one core)");
}

void check_physics_budget(double budget) {
  if (!(budget >= 1.0 && budget <= 1e15))
    throw core::InputError(fmt::format("--max-physics-steps = {} must be in [1, 1e15]", budget));
}

void check_procedure_cost(std::string_view procedure, const rig::ProcedureCost& cost,
                          const plant::TwinParams& twin, double budget, double repeats) {
  check_physics_budget(budget);
  const rig::CostEstimate e = rig::estimate_cost(cost, twin, repeats);
  if (const std::string why =
          rig::procedure_budget_problem(procedure, e, twin, budget, "--max-physics-steps");
      !why.empty())
    throw core::InputError(why);
}

}  // namespace piezoshift::app
