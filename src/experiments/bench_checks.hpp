#pragma once
// Checks every experiment makes on its bench before it trusts a number (validity.hpp): shared by
// the paper's experiments and the phase step; internal to the module.
#include <string>

#include <fmt/core.h>

#include "piezoshift/rig/bench.hpp"
#include "piezoshift/rig/validity.hpp"

namespace piezoshift::experiments::detail {

// "" when the loop is in authority at Z_d, else why not: a PID at its upper output limit, or at
// its lower one above Z_d = 0 (at rest, 0 V is where the stage sits).
inline std::string saturation_problem(const rig::Bench& bench, double zd_um) {
  const control::ControllerOutput& out = bench.last_output();
  const control::SemiClosedLoopParams& p = bench.controller_params();
  for (std::size_t i = 0; i < 3; ++i) {
    if (out.command_um[i] >= p.output_max_um)
      return fmt::format("PID {} at its upper output limit ({:g} um of command) at Z_d = {:g} um",
                         i + 1, p.output_max_um, zd_um);
    if (out.command_um[i] <= p.output_min_um && zd_um > 0.0)
      return fmt::format("PID {} at its lower output limit at Z_d = {:g} um", i + 1, zd_um);
  }
  return {};
}

// Marks v invalid when the bench's supervisor has latched a fault.
inline void check_fault(const rig::Bench& bench, rig::Validity& v, const char* during) {
  if (bench.faulted()) {
    const runtime::FaultRecord& f = bench.fault();
    v.fail(fmt::format("the safety supervisor tripped ({}, channel {}, at {:.3f} s) {}",
                       runtime::to_string(f.reason), f.channel + 1,
                       static_cast<double>(f.tick) * bench.sample_time_s(), during));
  }
}

}  // namespace piezoshift::experiments::detail
