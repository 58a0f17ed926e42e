#include "physics_budget.hpp"

namespace piezoshift::app {

void add_physics_budget_option(CLI::App* cmd, double& budget) {
  cmd->add_option("--max-physics-steps", budget,
                  "refuse a simulation estimated above this many physics steps (default 1e9, "
                  "about a minute of one core)");
}

}  // namespace piezoshift::app
