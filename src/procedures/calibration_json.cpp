#include "piezoshift/procedures/calibration_json.hpp"

namespace piezoshift::procedures {

nlohmann::json matrix_json(const control::Mat3& a) {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& row : a)
    rows.push_back({row[0], row[1], row[2]});
  return rows;
}

nlohmann::json paper_calibration_json(
    const control::SemiClosedLoopParams& controller,
    const calibration::MatrixIdentificationResult& matrix,
    const calibration::PolynomialIdentificationResult& polynomial) {
  const auto& g = controller.gains;
  const auto& p = controller.polynomial;
  return {{"pid_gains", {{"kp", g.kp}, {"ki", g.ki}, {"kd", g.kd}}},
          {"A", matrix_json(controller.matrix.a)},
          {"p", {p.p3, p.p2, p.p1, p.p0}},
          {"A_rms_residual_um", matrix.fit.rms_residual_um},
          {"condition_number", matrix.fit.condition_number},
          {"p_rms_residual_um", polynomial.fit.rms_residual_um}};
}

nlohmann::json fringe_calibration_json(const instrument::FringeCalibrationOutcome& r) {
  nlohmann::json j = paper_calibration_json(r.controller, r.matrix, r.polynomial);
  j["pupil_source"] = r.pupil_from_modulation ? "modulation" : "given";
  j["p_points"] = r.polynomial.command_um.size();
  j["p_skipped_commands"] = r.polynomial.saturated_points;
  j["frames"] = instrument::frames_read(r);
  j["stage2_simulated_s"] = r.stage2_simulated_s;
  j["stage3_simulated_s"] = r.stage3_simulated_s;
  j["wall_s"] = r.wall_time_s;
  return j;
}

}  // namespace piezoshift::procedures
