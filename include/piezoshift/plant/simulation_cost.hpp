#pragma once
// What a simulation of the twin will cost, estimated before it starts, and the budget it must fit
// (a config or a duration must not start a run that takes hours or exhausts memory).
// The twin's memory does not grow with the run (one buffer of kMaxPhysicsStepsPerTick forces at
// most, twin_ranges.hpp; 6 MB resident measured), so the cost is time: physics steps, measured at
// 57 ns (1e7 Hz physics) to 94 ns (the default 20 kHz, with the per-tick work) each on a shared
// two-core machine.
//
//   steps per tick = ceil(physics_rate_Hz * daq.sample_time_s)     (>= 1)
//   control ticks  = duration_s / daq.sample_time_s
//   physics steps  = control ticks * steps per tick
#include <string>
#include <string_view>

#include "piezoshift/plant/twin_params.hpp"

namespace piezoshift::plant {

//! The default budget: 1e9 physics steps, about 1 to 1.5 min of one core (50 000 s of simulated
//! time at the default 20 kHz physics). A caller raises it only on the user's explicit request.
inline constexpr double kDefaultPhysicsStepBudget = 1e9;

struct SimulationCost {
  double control_ticks = 0.0;
  double physics_steps = 0.0;
};

//! The cost of duration_s of simulated time (any duration_s >= 0; huge ones give huge costs, not
//! overflow: the arithmetic is in double).
SimulationCost estimate_simulation_cost(const TwinParams& twin, double duration_s);

//! "" when cost.physics_steps <= budget_physics_steps, else a message stating the estimate, the
//! budget and raise_option, the option that raises the budget.
std::string simulation_budget_problem(const SimulationCost& cost, double budget_physics_steps,
                                      std::string_view raise_option);

}  // namespace piezoshift::plant
