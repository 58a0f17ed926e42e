#pragma once
// The machine-readable summary of a reproduction (`reproduce --json`, DIR/summary.json): every
// Table 4 figure, the identified A and p, the calibration scores, and the times. Keys carry
// their unit (_um, _nm, _s, _pct).
#include <nlohmann/json.hpp>

#include "piezoshift/reproduction/reproduction.hpp"

namespace piezoshift::reproduction {

nlohmann::json summary_json(const ReproductionResult& r);

}  // namespace piezoshift::reproduction
