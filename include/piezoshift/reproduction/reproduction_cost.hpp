#pragma once
// What `reproduce` and `compare` cost on the simulated bench (rig/procedure_cost.hpp), measured
// with the simulation meter on the built-in configuration, seed 1, static_average_s = 1 and 2 s:
//
//                          fixed [s]   per second of static window [s]
//   reproduce              3654.2      1020
//   reproduce --quick      2298.5      1004
//   compare, one seed      5619.6      1601
//   compare --quick, seed  3502.9      1513.8
//   --fringes adds         1722.8       488.0   (the paper's schedule; 2026-11-27)
//   --fringes --quick adds 1174.8       486.0
//   --lock adds            4 (1.75 + H)   0      (H: --lock-hold-s; either schedule; 2026-11-27)
//
// (The default reproduction is 4674 s of simulated time, 9.3e7 physics steps.)
#include "piezoshift/reproduction/comparison.hpp"
#include "piezoshift/rig/procedure_cost.hpp"

namespace piezoshift::reproduction {

rig::ProcedureCost reproduce_cost(bool quick);
//! One seed of compare(); the seeds run one after the other.
rig::ProcedureCost compare_seed_cost(bool quick);
//! What `compare --fringes` adds to one seed: the calibration from fringes and the fourth
//! column's experiments (measured as compare with it minus compare without it).
rig::ProcedureCost compare_fringes_seed_cost(bool quick);
//! What `compare --lock --lock-hold-s hold_s` adds to one seed: four holds (comparison_hold.hpp),
//! each the hold and the ten measurements before it (their loop time, measured on seed 1).
rig::ProcedureCost compare_lock_seed_cost(double hold_s);
//! One seed of compare(options): compare_seed_cost(quick) plus what --fringes and --lock add.
rig::ProcedureCost compare_seed_cost(const CompareOptions& options);

}  // namespace piezoshift::reproduction
