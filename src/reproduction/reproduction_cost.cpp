#include "piezoshift/reproduction/reproduction_cost.hpp"

namespace piezoshift::reproduction {

rig::ProcedureCost reproduce_cost(bool quick) {
  return quick ? rig::ProcedureCost{2298.5, 1004.0} : rig::ProcedureCost{3654.2, 1020.0};
}

rig::ProcedureCost compare_seed_cost(bool quick) {
  // The improved calibration at 1 kHz has stage 5b (1.03 s); at 10 kHz it needs none.
  return quick ? rig::ProcedureCost{3503.88, 1513.82} : rig::ProcedureCost{5620.62, 1601.0};
}

rig::ProcedureCost compare_fringes_seed_cost(bool quick) {
  return quick ? rig::ProcedureCost{1174.80, 486.0} : rig::ProcedureCost{1722.80, 488.0};
}

rig::ProcedureCost compare_lock_seed_cost(double hold_s) {
  // The ten measurements' loop time before each hold, and the ramp: 1.75 s (seed 1, quick and
  // 5 or 60 s holds: compare's simulated time 27.0 and 247.0 s more with --lock).
  constexpr double kBeforeTheHold_s = 1.75;
  return rig::ProcedureCost{4.0 * (kBeforeTheHold_s + hold_s), 0.0};
}

rig::ProcedureCost compare_seed_cost(const CompareOptions& options) {
  rig::ProcedureCost c = compare_seed_cost(options.quick);
  const auto add = [&c](const rig::ProcedureCost& more) {
    c.fixed_s += more.fixed_s;
    c.window_s += more.window_s;
  };
  if (options.fringes)
    add(compare_fringes_seed_cost(options.quick));
  if (options.lock)
    add(compare_lock_seed_cost(options.lock_hold_s));
  return c;
}

}  // namespace piezoshift::reproduction
