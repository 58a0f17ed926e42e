#include "piezoshift/procedures/physics_budget.hpp"

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"

namespace piezoshift::procedures {

void check_physics_budget(double budget) {
  if (!(budget >= 1.0 && budget <= 1e15))
    throw core::InputError(fmt::format("--max-physics-steps = {} must be in [1, 1e15]", budget));
}

void check_procedure_cost(std::string_view procedure, const rig::ProcedureCost& cost,
                          const plant::TwinParams& twin, double budget, double repeats) {
  check_physics_budget(budget);
  rig::check_procedure_budget(procedure, cost, twin, budget, "--max-physics-steps", repeats);
}

}  // namespace piezoshift::procedures
