#pragma once
// --max-physics-steps on the command line; the checks are the procedures' own
// (procedures/physics_budget.hpp).
#include <CLI/CLI.hpp>

#include "piezoshift/procedures/physics_budget.hpp"

namespace piezoshift::app {

//! Adds --max-physics-steps to cmd, into budget (default plant::kDefaultPhysicsStepBudget).
void add_physics_budget_option(CLI::App* cmd, double& budget);

using procedures::check_physics_budget;
using procedures::check_procedure_cost;

}  // namespace piezoshift::app
