#include "piezoshift/procedures/measure_json.hpp"

#include <algorithm>
#include <cmath>

#include "piezoshift/instrument/hold_summary.hpp"

namespace piezoshift::procedures {

using Json = nlohmann::json;

namespace {

Json number_or_null(double v) {
  return std::isfinite(v) ? Json(v) : Json(nullptr);
}

Json number_or_null(const std::optional<double>& v) {
  return v ? Json(*v) : Json(nullptr);
}

Json text_or_null(const std::string& s) {
  return s.empty() ? Json(nullptr) : Json(s);
}

Json lock_json(const instrument::SequenceResult& s, const instrument::SequenceParams& p) {
  if (!s.lock)
    return nullptr;
  const instrument::LockSummary& l = *s.lock;
  return {{"gain_per_frame", p.lock ? Json(p.lock->lock.gain_per_frame) : Json(nullptr)},
          {"reference_frames", l.reference_frames},
          {"locked_frames", l.locked},
          {"holding_frames", l.holding},
          {"lost_frames", l.lost},
          {"retaken_frames", l.retaken},
          {"pupil_source", l.pupil_from_modulation ? "modulation" : "given"},
          {"pupil_pixels", l.pupil_pixels},
          {"first_refusal", text_or_null(l.first_refusal)},
          {"correction_piston_nm", l.correction[0]},
          {"correction_theta_x_urad", l.correction[1]},
          {"correction_theta_y_urad", l.correction[2]}};
}

Json timing_json(const instrument::SequenceResult& s) {
  return {{"wall_time_s", s.wall_time_s},
          {"floor_s", s.floor_s},
          {"ratio_to_floor",
           s.floor_s > 0.0 ? number_or_null(s.wall_time_s / s.floor_s) : Json(nullptr)},
          {"loop_time_s", s.loop_time_s},
          {"ticks", s.ticks},
          {"overruns", s.overruns}};
}

}  // namespace

double stage_error_rms_nm(double measured_rms_nm, double floor_rms_nm) {
  return std::sqrt(std::max(0.0, measured_rms_nm * measured_rms_nm - floor_rms_nm * floor_rms_nm));
}

Json exposures_json(const instrument::SequenceResult& s) {
  Json a = Json::array();
  for (const instrument::ExposureRecord& e : s.exposures) {
    Json j{{"average", e.average + 1},
           {"frame", e.frame},
           {"frame_id", e.frame_id},
           {"commanded_step_rad", e.commanded_step_rad},
           {"commanded_piston_nm", e.commanded_piston_nm},
           {"move_time_s", e.move_time_s},
           {"settle_s", e.settled_time_s - e.move_time_s},
           {"trigger_time_s", e.trigger_time_s},
           {"exposure_end_s", e.exposure_end_s},
           {"gauge_error_mean_nm", e.gauge_error_mean_nm},
           {"gauge_error_max_nm", e.gauge_error_max_nm},
           {"arrival_wall_s", e.arrival_wall_s}};
    if (!e.lock_state.empty()) {
      j["lock_state"] = e.lock_state;
      j["lock_correction_nm"] = number_or_null(e.lock_correction_nm);
      j["fringe_piston_nm"] = number_or_null(e.fringe_piston_nm);
      j["lock_reason"] = text_or_null(e.lock_reason);
      j["retakes"] = e.retakes;
    }
    if (e.has_truth) {
      j["truth_piston_nm"] = e.truth_piston_nm;
      j["truth_blur_nm"] = e.truth_blur_nm;
      j["truth_tip_urad"] = e.truth_tip_urad;
      j["truth_tilt_urad"] = e.truth_tilt_urad;
    }
    a.push_back(j);
  }
  return a;
}

Json hold_json(const instrument::SequenceResult& s) {
  const instrument::HoldSummary h = instrument::hold_summary(s);
  return {{"frames", h.frames},
          {"span_s", h.span_s},
          {"frame_interval_s", number_or_null(h.frame_interval_s)},
          {"path_error_rms_nm", number_or_null(h.path_error_rms_nm)},
          {"path_error_max_nm", number_or_null(h.path_error_max_nm)},
          {"path_error_1s_means_rms_nm", number_or_null(h.path_error_1s_means_rms_nm)},
          {"lock_states", h.lock_states.empty() ? Json(nullptr) : Json(h.lock_states)}};
}

Json measure_json(const MeasureOutcome& o, const MeasureWritten& written) {
  const instrument::SequenceResult& s = o.sequence;
  if (!s.validity.valid || !o.analysis)
    return {{"valid", false}, {"reason", s.validity.valid ? o.reason : s.validity.reason}};
  const instrument::MeasurementAnalysis& a = *o.analysis;
  const instrument::SequenceParams& p = o.params;
  Json j{
      {"camera", o.camera},
      {"daq", o.daq},
      {"trigger", instrument::to_string(p.trigger)},
      {"rate_Hz", o.rate_Hz},
      {"clock", o.real_time ? "realtime" : "free-run"},
      {"calibration", o.calibration_source},
      {"algorithm", o.algorithm},
      {"wavelength_nm", p.wavelength_nm},
      {"frames", p.steps_rad.size()},
      {"averages", p.averages},
      {"commanded_steps_rad", p.steps_rad},
      {"recovered_steps_rad", a.recovered_steps_rad},
      {"true_steps_rad", a.true_steps_rad.empty() ? Json(nullptr) : Json(a.true_steps_rad)},
      {"step_error_max_mrad", a.has_step_error() ? Json(a.step_error_max_mrad) : Json(nullptr)},
      {"steps_reason", text_or_null(a.steps_reason)},
      {"converged", a.converged},
      {"reason", text_or_null(a.reason)},
      {"surface_rms_nm", a.figures.rms},
      {"surface_pv_nm", a.figures.pv},
      {"surface_pvr_nm", a.figures.pvr},
      {"valid_pixels", a.figures.pixels},
      {"zernike_nm", a.zernike_nm},
      {"error_rms_nm", number_or_null(o.error_rms_nm)},
      {"ideal_error_rms_nm", number_or_null(o.ideal_error_rms_nm)},
      {"floor_error_rms_nm", number_or_null(o.floor_error_rms_nm)},
      {"stage_error_rms_nm", o.floor_error_rms_nm && o.error_rms_nm
                                 ? Json(stage_error_rms_nm(*o.error_rms_nm, *o.floor_error_rms_nm))
                                 : Json(nullptr)},
      {"timing", timing_json(s)},
      {"exposures", exposures_json(s)}};
  // The cavity's path from its set point after the first average (the lock's reference).
  j["path_error_rms_nm"] = number_or_null(instrument::path_error_rms_nm(s, p.steps_rad.size()));
  j["lock"] = lock_json(s, p);
  j["hold"] = s.hold.empty() ? Json(nullptr) : hold_json(s);
  Json averages = Json::array();
  for (const psi::SurfaceFigures& f : a.average_figures)
    averages.push_back({{"rms_nm", f.rms}, {"pv_nm", f.pv}, {"pvr_nm", f.pvr}});
  j["average_figures"] = averages;
  if (!written.out.empty())
    j["out"] = written.out;
  if (!written.out_given.empty())
    j["out_given"] = written.out_given;
  j["lateral_scale_m_per_px"] = o.m_per_px > 0.0 ? Json(o.m_per_px) : Json(nullptr);
  return j;
}

}  // namespace piezoshift::procedures
