#pragma once
// What a procedure on the simulated bench will cost, estimated before it starts, against the
// budget `simulate` already keeps (plant/simulation_cost.hpp): an in-range setting such
// as static_average_s = 1e6 must not start a calibration that takes 28 hours.
//
// A procedure's simulated time is fixed_s plus window_s per second of the interferometer's
// static window (static_average_s): each static measurement waits for the next whole window,
// between one and two of them. Both numbers are measured with simulation_meter.hpp on the
// built-in configuration at static_average_s = 1 and 2 s; tests/rig/procedure_cost_test.cpp and
// the reproduction tests hold the estimates to the meter. The physics steps follow from the
// twin's rates as for `simulate`: ceil(physics_rate_Hz T) per control tick of T.
#include <string>
#include <string_view>

#include "piezoshift/plant/twin_params.hpp"

namespace piezoshift::rig {

struct ProcedureCost {
  double fixed_s = 0.0;   //!< simulated seconds that do not depend on the static window
  double window_s = 0.0;  //!< simulated seconds per second of static_average_s
};

struct CostEstimate {
  double simulated_s = 0.0;
  double physics_steps = 0.0;
};

//! The estimate of `repeats` runs of the procedure on this twin.
CostEstimate estimate_cost(const ProcedureCost& cost, const plant::TwinParams& twin,
                           double repeats = 1.0);

//! "" when the estimate fits budget_physics_steps; else a message naming the procedure, the
//! estimate (physics steps, simulated time, the settings that set them) and raise_option.
std::string procedure_budget_problem(std::string_view procedure, const CostEstimate& estimate,
                                     const plant::TwinParams& twin, double budget_physics_steps,
                                     std::string_view raise_option);

//! core::InputError carrying procedure_budget_problem()'s message when repeats x cost is above
//! budget_physics_steps on this twin; nothing otherwise.
void check_procedure_budget(std::string_view procedure, const ProcedureCost& cost,
                            const plant::TwinParams& twin, double budget_physics_steps,
                            std::string_view raise_option, double repeats = 1.0);

}  // namespace piezoshift::rig
