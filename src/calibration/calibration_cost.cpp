#include "piezoshift/calibration/calibration_cost.hpp"

namespace piezoshift::calibration {

rig::ProcedureCost calibration_cost(const CalibrationOptions& options, double sample_time_s) {
  const PidTuningOptions& p = options.pid_tuning;
  const double candidates =
      static_cast<double>(p.kp_values.size() * p.ki_values.size() * p.kd_values.size());
  const double per_candidate_s = 0.2 + p.step_duration_s + sample_time_s;
  return {82.5 + (candidates > 1.0 ? candidates - 1.0 : 0.0) * per_candidate_s, 76.0};
}

rig::ProcedureCost improved_calibration_cost() {
  // 277.78 s before stage 7, whose two trials take 2 x 0.5 s; stage 5b 1.03 s.
  return {279.81, 73.0};
}

}  // namespace piezoshift::calibration
