#pragma once
// What the simulated benches of this process have run so far: control ticks, simulated seconds
// and static interferometer measurements, summed over every Bench (each procedure opens several
// sessions). The procedures' cost estimates (procedure_cost.hpp) are checked against it.
#include <cstdint>

namespace piezoshift::rig {

struct SimulationMeter {
  std::uint64_t ticks = 0;
  double simulated_s = 0.0;
  std::uint64_t static_measurements = 0;
  std::uint64_t physics_steps = 0;
};

//! The totals so far (thread-safe; each counter is read on its own).
SimulationMeter simulation_meter() noexcept;

}  // namespace piezoshift::rig
