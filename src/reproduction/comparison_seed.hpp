#pragma once
// compare's runs on one seed (comparison.hpp): the paper's and the improved controller each
// calibrated by its own procedure, the oracle feedback on the paper's calibration with the gains
// its ring test holds, the 10 kHz figures, and the opt-in fringe column and holds. Private to
// the module: compare() runs it per seed, summarize_comparison() takes its results.
#include <cstdint>

#include "piezoshift/config/project_config.hpp"
#include "piezoshift/reproduction/comparison.hpp"
#include "piezoshift/rig/progress.hpp"

namespace piezoshift::reproduction::detail {

SeedComparison compare_seed(const config::ProjectConfig& config, std::uint64_t seed,
                            const Schedule& s, const CompareOptions& options,
                            const rig::Progress& progress);

}  // namespace piezoshift::reproduction::detail
