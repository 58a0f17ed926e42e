#pragma once
// The one budget of simulated work every procedure that runs the twin checks before it starts
// (--max-physics-steps; rig/procedure_cost.hpp; `simulate` checks its own run the same way,
// plant/simulation_cost.hpp).
#include <string_view>

#include "piezoshift/plant/simulation_cost.hpp"
#include "piezoshift/rig/procedure_cost.hpp"

namespace piezoshift::procedures {

//! InputError when budget is outside [1, 1e15].
void check_physics_budget(double budget);

//! InputError naming the procedure, its estimate and the option when repeats x cost is above
//! the budget on this twin.
void check_procedure_cost(std::string_view procedure, const rig::ProcedureCost& cost,
                          const plant::TwinParams& twin, double budget, double repeats = 1.0);

}  // namespace piezoshift::procedures
