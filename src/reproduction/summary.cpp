#include "piezoshift/reproduction/summary.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

namespace piezoshift::reproduction {
namespace {

nlohmann::json matrix_json(const control::Mat3& a) {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& row : a)
    rows.push_back({row[0], row[1], row[2]});
  return rows;
}

nlohmann::json poly_json(const control::CubicPolynomial& p) {
  return {p.p3, p.p2, p.p1, p.p0};
}

// JSON has no infinity: a time that never came (not settled) is null.
nlohmann::json time_or_null(double t) {
  return std::isfinite(t) ? nlohmann::json(t) : nlohmann::json();
}

nlohmann::json trial_json(const calibration::PidTrial& t) {
  nlohmann::json per = nlohmann::json::array();
  for (const auto& s : t.per_actuator) {
    per.push_back({{"overshoot_pct", s.overshoot_pct},
                   {"settling_time_s", time_or_null(s.settling_time_s)},
                   {"steady_state_error_nm", s.steady_state_error_nm}});
  }
  return {{"kp", t.gains.kp},
          {"ki", t.gains.ki},
          {"kd", t.gains.kd},
          {"acceptable", t.acceptable},
          {"worst_overshoot_pct", t.worst.overshoot_pct},
          {"worst_settling_time_s", time_or_null(t.worst.settling_time_s)},
          {"worst_steady_state_error_nm", t.worst.steady_state_error_nm},
          {"per_actuator", per}};
}

// Table 4's figures and the extra sweeps of one controller, keys prefixed.
void set_json(nlohmann::json& j, const std::string& prefix, const ExperimentSet& e) {
  const auto& step = e.step.metrics;
  j[prefix + "travel_open_loop_um"] = e.travel.open_loop_um;
  j[prefix + "travel_semi_closed_um"] = e.travel.semi_closed_um;
  j[prefix + "step_um"] = step.step_um;
  j[prefix + "step_rise_time_s"] = time_or_null(step.rise_time_s);
  j[prefix + "step_overshoot_pct"] = step.overshoot_pct;
  j[prefix + "step_truth_overshoot_pct"] = e.step.truth_overshoot_pct;
  j[prefix + "step_settling_time_s"] = time_or_null(step.settling_time_pct_s);
  j[prefix + "step_settling_time_10nm_s"] = time_or_null(step.settling_time_abs_s);
  j[prefix + "linearity_zero_end_pct"] = e.linearity.metrics.linearity_zero_end_pct;
  j[prefix + "linearity_best_fit_pct"] = e.linearity.metrics.linearity_best_fit_pct;
  j[prefix + "linearity_grid_zero_end_pct"] = e.linearity_grid.metrics.linearity_zero_end_pct;
  j[prefix + "linearity_grid_best_fit_pct"] = e.linearity_grid.metrics.linearity_best_fit_pct;
  j[prefix + "linearity_down_zero_end_pct"] = e.linearity_down.metrics.linearity_zero_end_pct;
  j[prefix + "linearity_down_best_fit_pct"] = e.linearity_down.metrics.linearity_best_fit_pct;
  j[prefix + "repeatability_5um_nm"] = e.repeat_5um.metrics.repeatability_nm;
  j[prefix + "repeatability_10um_nm"] = e.repeat_10um.metrics.repeatability_nm;
  j[prefix + "repeatability_5um_n"] = e.repeat_5um.metrics.n;
  j[prefix + "repeatability_10um_n"] = e.repeat_10um.metrics.n;
  j[prefix + "phase_step_nm"] = e.phase_step.step_nm;
  j[prefix + "phase_step_hold_jitter_nm_rms"] = e.phase_step.hold_jitter_nm_rms;
  j[prefix + "phase_step_settling_time_s"] = time_or_null(e.phase_step.settling_time_s);
  j[prefix + "phase_step_final_error_nm"] = e.phase_step.final_error_nm;
  j[prefix + "phase_step_own_settling_time_s"] = time_or_null(e.phase_step.own_settling_time_s);
  j[prefix + "phase_step_still_wander_nm"] = e.phase_step.still_wander_nm;
  j[prefix + "valid"] = e.table4_valid();
  j[prefix + "invalid_reasons"] = e.invalid_reasons();
  const auto validity = [](const rig::Validity& v) {
    return nlohmann::json{{"valid", v.valid}, {"reason", v.reason}};
  };
  j[prefix + "validity"] = {{"travel", validity(e.travel.validity)},
                            {"step", validity(e.step.validity)},
                            {"linearity", validity(e.linearity.validity)},
                            {"linearity_grid", validity(e.linearity_grid.validity)},
                            {"linearity_down", validity(e.linearity_down.validity)},
                            {"repeatability_5um", validity(e.repeat_5um.validity)},
                            {"repeatability_10um", validity(e.repeat_10um.validity)},
                            {"phase_step", validity(e.phase_step.validity)}};
}

// The phase-shifting measurement, keys prefixed measurement_; its numbers only when valid.
void measurement_json(nlohmann::json& j, const PhaseMeasurement& m) {
  j["validity"]["measurement"] = {{"valid", m.validity.valid}, {"reason", m.validity.reason}};
  j["measurement_valid"] = m.validity.valid;
  j["measurement_algorithm"] = m.algorithm;
  j["measurement_seed"] = m.scene.seed;
  j["measurement_commanded_steps_rad"] = m.params.steps_rad;
  nlohmann::json settle = nlohmann::json::array();
  for (const instrument::ExposureRecord& e : m.sequence.exposures)
    settle.push_back(e.settled_time_s - e.move_time_s);
  j["measurement_settle_s"] = settle;
  j["measurement_simulated_time_s"] = m.simulated_time_s;
  if (!m.validity.valid)
    return;
  const psi::SurfaceFigures& f = m.analysis.figures;
  j["measurement_surface_rms_nm"] = f.rms;
  j["measurement_surface_pv_nm"] = f.pv;
  j["measurement_surface_pvr_nm"] = f.pvr;
  j["measurement_error_rms_nm"] = m.error_rms_nm;
  j["measurement_ideal_error_rms_nm"] = m.ideal_error_rms_nm;
  j["measurement_recovered_steps_rad"] = m.analysis.recovered_steps_rad.front();
  j["measurement_true_steps_rad"] = m.analysis.true_steps_rad.front();
  j["measurement_step_error_max_mrad"] = m.analysis.step_error_max_mrad;
  j["measurement_zernike_nm"] = m.analysis.zernike_nm;
}

}  // namespace

nlohmann::json summary_json(const ReproductionResult& r) {
  const auto& cal = r.calibration;
  nlohmann::json j;
  j["seed"] = r.options.seed;
  j["schedule"] = r.options.quick ? "quick" : "paper";
  j["pid"] = r.options.pid == calibration::PidChoice::kPaper ? "paper" : "search";
  set_json(j, "", r);
  set_json(j, "oracle_", r.oracle);
  // reproduce's own validity: Table 4 and the measurement (set_json's is the set's).
  j["valid"] = r.valid();
  j["invalid_reasons"] = r.invalid_reasons();
  measurement_json(j, r.measurement);
  const auto& raw = r.linearity_without_cubic;
  j["linearity_without_cubic_zero_end_pct"] = raw.metrics.linearity_zero_end_pct;
  j["linearity_without_cubic_best_fit_pct"] = raw.metrics.linearity_best_fit_pct;
  j["linearity_without_cubic_valid"] = raw.validity.valid;
  // The calibrated PID's stability margins on the identified loop, the worst of the channels.
  for (const InnerLoopAnalysis& a : r.inner_loop) {
    const std::string at = fmt::format("pid_margins_{:g}kHz_", 1e-3 / a.sample_time_s);
    j[at + "valid"] = a.validity.valid;
    if (!a.validity.valid) {
      j[at + "reason"] = a.validity.reason;
      continue;
    }
    const runtime::StabilityMargins w = a.worst();
    const double gm = w.gain_margin_dB, pm = w.phase_margin_deg, fc = w.gain_crossover_Hz;
    j[at + "gain_margin_dB"] = std::isfinite(gm) ? nlohmann::json(gm) : nlohmann::json();
    j[at + "phase_margin_deg"] = std::isfinite(pm) ? nlohmann::json(pm) : nlohmann::json();
    j[at + "gain_crossover_Hz"] = std::isfinite(fc) ? nlohmann::json(fc) : nlohmann::json();
  }
  j["identified_A"] = matrix_json(cal.controller.matrix.a);
  j["identified_A_condition_number"] = cal.matrix.fit.condition_number;
  j["identified_A_rms_residual_um"] = cal.matrix.fit.rms_residual_um;
  j["fitted_p"] = poly_json(cal.controller.polynomial);
  j["fitted_p_rms_residual_um"] = cal.polynomial.fit.rms_residual_um;
  j["fitted_p_saturated_points"] = cal.polynomial.saturated_points;
  j["pid_gains"] = {{"kp", cal.controller.gains.kp},
                    {"ki", cal.controller.gains.ki},
                    {"kd", cal.controller.gains.kd},
                    {"sample_time_s", cal.controller.gains_sample_time_s}};
  j["pid_step_target_um"] = {cal.pid.step_target_um[0], cal.pid.step_target_um[1],
                             cal.pid.step_target_um[2]};
  j["pid_paper_score"] = trial_json(cal.pid.paper);
  j["pid_search_best"] = trial_json(cal.pid.best);
  j["pid_search_trials"] = cal.pid.trials.size();
  j["simulated_time_s"] = r.simulated_time_s;
  j["wall_time_s"] = r.wall_time_s;
  return j;
}

}  // namespace piezoshift::reproduction
