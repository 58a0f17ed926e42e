#pragma once
// Progress of a long offline job (calibration, experiments): called with the work done so far
// and the total, in whatever unit the job counts (trials, moves, seconds), and a short label.
#include <functional>
#include <string_view>

namespace piezoshift::rig {

using Progress = std::function<void(double done, double total, std::string_view label)>;

}  // namespace piezoshift::rig
