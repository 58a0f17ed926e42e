// Python binding of the instrument module (docs/python.md, "Cameras and measurements"): measure()
// takes one phase-shifting measurement on the twin as `piezoshift measure --daq sim --free-run`
// does (the shipping loop in owner mode on a simulated clock, the camera exposing once the stage
// has settled, then the analysis) and returns its result as a dict with the JSON names of
// `measure --json`, plus the maps and frames as numpy arrays. The fringe lock (`lock`) and the
// hold after the measurement (`hold_s`) are the CLI's: the lock built and checked by
// instrument::measurement_lock_setup, the hold summed up by instrument::hold_summary, both shared
// with `measure --lock --hold-s`, and its records as hold.csv's columns. A measurement that is not
// valid or whose fits did not converge raises ProcedureFailed (the CLI's exit status 4), the
// partial result in its `result` attribute.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "bindings.hpp"
#include "images.hpp"
#include "piezoshift/calibration/calibration_cost.hpp"
#include "piezoshift/calibration/loop_calibration.hpp"
#include "piezoshift/camera/instrument_config.hpp"
#include "piezoshift/camera/make_camera.hpp"
#include "piezoshift/camera/twin_camera.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/instrument/acquisition.hpp"
#include "piezoshift/instrument/fringe_calibration.hpp"
#include "piezoshift/instrument/hold_summary.hpp"
#include "piezoshift/instrument/measurement.hpp"
#include "piezoshift/instrument/measurement_lock.hpp"
#include "piezoshift/instrument/twin_floor.hpp"
#include "piezoshift/plant/simulation_cost.hpp"
#include "piezoshift/psi/pupil_detection.hpp"
#include "piezoshift/rig/procedure_cost.hpp"
#include "piezoshift/rig/validity.hpp"
#include "piezoshift/runtime/loop_clock.hpp"
#include "piezoshift/runtime/sim_backend.hpp"
#include "values.hpp"

namespace piezoshift::python {

namespace {

namespace cam = ps::camera;
namespace ins = ps::instrument;
namespace psi = ps::psi;

constexpr double kWavelength_nm = 632.8;  // the CLI's: HeNe

struct MeasureArgs {
  std::optional<std::string> config;
  std::variant<std::monostate, std::string, ps::control::SemiClosedLoopParams> calibration;
  std::string camera = "twin";
  std::string algorithm = "hariharan5";
  std::vector<double> steps_rad;
  int averages = 1;
  std::string surface;
  std::uint64_t seed = 1;
  double rate_Hz = 1000.0;
  double base_um = 5.0;
  psi::OnTarget on_target{};
  double frame_timeout_s = 2.0;
  py::object mask;
  std::string trigger = "software";
  bool lock = false;
  double lock_retake_s = ins::LockSetup{}.retake_s;
  double hold_s = 0.0;
};

// Aravis's in-process fake camera shown the twin's fringes, as `measure --daq sim` does.
bool fed_by_twin(const std::string& spec) {
  return spec.starts_with("aravis:Fake");
}

// The commanded steps and the sequence, checked as the CLI checks them.
ins::SequenceParams sequence_params(const MeasureArgs& a, psi::Algorithm alg) {
  ins::SequenceParams p;
  p.steps_rad = ins::commanded_steps(alg, a.steps_rad, "steps_rad");
  p.wavelength_nm = kWavelength_nm;
  p.base_um = a.base_um;
  p.on_target = a.on_target;
  p.averages = a.averages;
  p.frame_timeout_s = a.frame_timeout_s;
  p.hold_s = a.hold_s;
  p.trigger = a.trigger == "line" ? ins::TriggerMode::kLine : ins::TriggerMode::kSoftware;
  if (const std::string why = ins::sequence_problem(p); !why.empty())
    throw ps::core::InputError("measure: " + why);
  return p;
}

using ps::calibration::LoopCalibration;

// A file or a controller, checked at the loop's rate; none: the twin calibrated first with the
// paper's procedure and gains, as `measure` on the twin does without --calibration.
LoopCalibration resolve(const MeasureArgs& a, const ps::config::ProjectConfig& config) {
  const double ts = 1.0 / a.rate_Hz;
  if (const auto* path = std::get_if<std::string>(&a.calibration))
    return ps::calibration::load_loop_calibration(*path, ts);
  if (const auto* p = std::get_if<ps::control::SemiClosedLoopParams>(&a.calibration)) {
    LoopCalibration c;
    c.params = *p;
    c.source = "a controller from Python";
    ps::calibration::check_at_loop_rate(c.params, ts, c.source);
    return c;
  }
  return ps::calibration::startup_calibration(config, a.seed, ps::plant::kDefaultPhysicsStepBudget,
                                              "a calibration file or controller");
}

void check_args(const MeasureArgs& a) {
  if (!(a.rate_Hz >= 1000.0 && a.rate_Hz <= 10000.0))
    throw ps::core::InputError("rate_Hz " + std::to_string(a.rate_Hz) + ": must be in 1000..10000");
  if (a.averages < 1 || a.averages > 100)
    throw ps::core::InputError("averages " + std::to_string(a.averages) + ": must be in 1..100");
  if (a.camera != "twin" && !fed_by_twin(a.camera) && !a.surface.empty())
    throw ps::core::InputError(
        "surface: the test surface of the twin camera (or of aravis:Fake_1)");
  if (a.trigger != "software" && a.trigger != "line")
    throw ps::core::InputError("trigger '" + a.trigger + "': expected software or line");
  if (a.trigger == "line" && fed_by_twin(a.camera))
    throw ps::core::InputError("trigger: camera " + a.camera +
                               " has no line input (Aravis's fake camera free-runs at 25 Hz "
                               "on a line trigger); use software");
  if ((a.camera == "twin" || fed_by_twin(a.camera)) && !a.mask.is_none())
    throw ps::core::InputError("mask: the twin camera's pupil is its scene's; give none");
}

std::unique_ptr<cam::Camera> open_camera(const MeasureArgs& a, const cam::CameraConfig& cc,
                                         const cam::TwinScene* scene) {
  std::unique_ptr<cam::Camera> c = cam::make_camera(a.camera, cc, scene);
  c->start();
  return c;
}

py::object number_or_none(std::optional<double> v) {
  return v ? py::object(py::float_(*v)) : py::object(py::none());
}

// NaN (no lock, no pose) as None, as the CLI's JSON writes null.
py::object finite_or_none(double v) {
  return number_or_none(std::isfinite(v) ? std::optional<double>(v) : std::nullopt);
}

py::object text_or_none(const std::string& s) {
  return s.empty() ? py::object(py::none()) : py::object(py::str(s));
}

py::list exposures_list(const ins::SequenceResult& s) {
  py::list out;
  for (const ins::ExposureRecord& e : s.exposures) {
    py::dict d;
    d["average"] = e.average + 1;
    d["frame"] = e.frame;
    d["frame_id"] = e.frame_id;
    d["commanded_step_rad"] = e.commanded_step_rad;
    d["commanded_piston_nm"] = e.commanded_piston_nm;
    d["move_time_s"] = e.move_time_s;
    d["settle_s"] = e.settled_time_s - e.move_time_s;
    d["trigger_time_s"] = e.trigger_time_s;
    d["exposure_end_s"] = e.exposure_end_s;
    d["gauge_error_mean_nm"] = e.gauge_error_mean_nm;
    d["gauge_error_max_nm"] = e.gauge_error_max_nm;
    d["arrival_wall_s"] = e.arrival_wall_s;
    if (!e.lock_state.empty()) {
      d["lock_state"] = e.lock_state;
      d["lock_correction_nm"] = finite_or_none(e.lock_correction_nm);
      d["fringe_piston_nm"] = finite_or_none(e.fringe_piston_nm);
      d["lock_reason"] = text_or_none(e.lock_reason);
      d["retakes"] = e.retakes;
    }
    if (e.has_truth) {
      d["truth_piston_nm"] = e.truth_piston_nm;
      d["truth_blur_nm"] = e.truth_blur_nm;
      d["truth_tip_urad"] = e.truth_tip_urad;
      d["truth_tilt_urad"] = e.truth_tilt_urad;
    }
    out.append(d);
  }
  return out;
}

py::object lock_dict(const ins::SequenceResult& s, const ins::SequenceParams& p) {
  if (!s.lock)
    return py::none();
  const ins::LockSummary& l = *s.lock;
  py::dict d;
  d["gain_per_frame"] = p.lock ? py::object(py::float_(p.lock->lock.gain_per_frame)) : py::none();
  d["reference_frames"] = l.reference_frames;
  d["locked_frames"] = l.locked;
  d["holding_frames"] = l.holding;
  d["lost_frames"] = l.lost;
  d["retaken_frames"] = l.retaken;
  d["pupil_source"] = l.pupil_from_modulation ? "modulation" : "given";
  d["pupil_pixels"] = l.pupil_pixels;
  d["first_refusal"] = text_or_none(l.first_refusal);
  d["correction_piston_nm"] = l.correction[0];
  d["correction_theta_x_urad"] = l.correction[1];
  d["correction_theta_y_urad"] = l.correction[2];
  return d;
}

// The hold's records as hold.csv's columns, each an array over the hold's frames.
py::dict hold_records(const ins::SequenceResult& s, const ins::HoldSummary& h) {
  std::vector<double> t, settle, gauge, correction, fringe;
  std::vector<std::uint64_t> ids;
  py::list states;
  for (const ins::ExposureRecord& e : s.hold) {
    t.push_back(e.trigger_time_s);
    ids.push_back(e.frame_id);
    settle.push_back(e.settled_time_s - e.move_time_s);
    gauge.push_back(e.gauge_error_mean_nm);
    correction.push_back(e.lock_correction_nm);
    fringe.push_back(e.fringe_piston_nm);
    states.append(e.lock_state);
  }
  py::dict r;
  r["trigger_time_s"] = to_numpy(t);
  r["frame_id"] = py::array_t<std::uint64_t>(static_cast<py::ssize_t>(ids.size()), ids.data());
  r["settle_s"] = to_numpy(settle);
  r["gauge_error_mean_nm"] = to_numpy(gauge);
  r["path_error_nm"] =
      h.path_error_nm.empty() ? py::object(py::none()) : py::object(to_numpy(h.path_error_nm));
  r["lock_correction_nm"] = to_numpy(correction);
  r["fringe_piston_nm"] = to_numpy(fringe);
  r["lock_state"] = states;
  return r;
}

// measure --json's `hold`, and its records.
py::object hold_dict(const ins::SequenceResult& s) {
  if (s.hold.empty())
    return py::none();
  const ins::HoldSummary h = ins::hold_summary(s);
  py::dict d;
  d["frames"] = h.frames;
  d["span_s"] = h.span_s;
  d["frame_interval_s"] = number_or_none(h.frame_interval_s);
  d["path_error_rms_nm"] = number_or_none(h.path_error_rms_nm);
  d["path_error_max_nm"] = number_or_none(h.path_error_max_nm);
  d["path_error_1s_means_rms_nm"] = number_or_none(h.path_error_1s_means_rms_nm);
  d["lock_states"] = h.lock_states.empty() ? py::object(py::none()) : py::cast(h.lock_states);
  d["records"] = hold_records(s, h);
  return d;
}

// The acquisition's part of the result: frames, exposures, timing, validity.
py::dict sequence_dict(const ins::SequenceResult& s, const ins::SequenceParams& p,
                       const std::string& camera_name, const LoopCalibration& c,
                       psi::Algorithm alg) {
  py::dict d;
  d["camera"] = camera_name;
  d["daq"] = "sim";
  d["trigger"] = ins::to_string(p.trigger);
  d["clock"] = "free-run";
  d["calibration"] = c.source;
  d["algorithm"] = std::string(psi::algorithm_name(alg));
  d["wavelength_nm"] = p.wavelength_nm;
  d["averages"] = p.averages;
  d["commanded_steps_rad"] = p.steps_rad;
  d["valid"] = s.validity.valid;
  d["valid_reason"] =
      s.validity.reason.empty() ? py::object(py::none()) : py::object(py::str(s.validity.reason));
  py::list frames;
  for (const cam::Frame& f : s.frames)
    frames.append(counts_to_numpy(f));
  d["frames"] = frames;
  d["exposures"] = exposures_list(s);
  // The cavity's path from its set point after the first average (the lock's reference).
  d["path_error_rms_nm"] = number_or_none(ins::path_error_rms_nm(s, p.steps_rad.size()));
  d["lock"] = lock_dict(s, p);
  d["hold"] = hold_dict(s);
  py::dict t;
  t["wall_time_s"] = s.wall_time_s;
  t["floor_s"] = s.floor_s;
  t["ratio_to_floor"] =
      s.floor_s > 0.0 ? py::object(py::float_(s.wall_time_s / s.floor_s)) : py::object(py::none());
  t["loop_time_s"] = s.loop_time_s;
  t["ticks"] = s.ticks;
  t["overruns"] = s.overruns;
  d["timing"] = t;
  return d;
}

void add_analysis(py::dict& d, const ins::MeasurementAnalysis& a) {
  d["surface_nm"] = map_to_numpy(a.surface_nm);
  d["valid_pixels_mask"] = mask_to_numpy(a.valid);
  d["recovered_steps_rad"] = a.recovered_steps_rad;
  d["true_steps_rad"] =
      a.true_steps_rad.empty() ? py::object(py::none()) : py::object(py::cast(a.true_steps_rad));
  d["step_error_max_mrad"] = a.true_steps_rad.empty()
                                 ? py::object(py::none())
                                 : py::object(py::float_(a.step_error_max_mrad));
  d["converged"] = a.converged;
  d["reason"] = a.reason.empty() ? py::object(py::none()) : py::object(py::str(a.reason));
  d["surface_rms_nm"] = a.figures.rms;
  d["surface_pv_nm"] = a.figures.pv;
  d["surface_pvr_nm"] = a.figures.pvr;
  d["valid_pixels"] = a.figures.pixels;
  d["zernike_nm"] = a.zernike_nm;
  py::list averages;
  for (const psi::SurfaceFigures& f : a.average_figures) {
    py::dict af;
    af["rms_nm"] = f.rms;
    af["pv_nm"] = f.pv;
    af["pvr_nm"] = f.pvr;
    averages.append(af);
  }
  d["average_figures"] = averages;
}

// Raises piezoshift.ProcedureFailed with the partial result attached.
[[noreturn]] void fail(const std::string& why, const py::dict& partial) {
  const py::object type = py::module_::import("piezoshift._piezoshift").attr("ProcedureFailed");
  py::object error = type(why);
  error.attr("result") = partial;
  PyErr_SetObject(type.ptr(), error.ptr());
  throw py::error_already_set();
}

struct Setup {
  cam::InstrumentConfig config;
  psi::Algorithm algorithm = psi::Algorithm::kHariharan5;
  ins::SequenceParams params;
  std::optional<cam::TwinScene> scene;
  LoopCalibration calibration;
};

// Everything before the loop starts, in the CLI's order so that bad input is named first.
Setup prepare(const MeasureArgs& a) {
  check_args(a);
  Setup s;
  if (a.config)
    s.config = cam::load_instrument_config(*a.config);
  s.algorithm = psi::parse_algorithm(a.algorithm);
  s.params = sequence_params(a, s.algorithm);
  if (a.trigger == "line")
    s.config.camera.settings.trigger = cam::TriggerSource::kLine;
  if (a.camera == "twin" || fed_by_twin(a.camera)) {
    const psi::SurfaceSpec spec =
        a.surface.empty() ? psi::SurfaceSpec{} : psi::parse_surface_spec(a.surface);
    s.scene = cam::make_twin_scene(
        spec,
        cam::measurement_optics(s.config.camera.settings, s.config.camera.pupil_radius_m,
                                kWavelength_nm),
        a.seed);
  }
  return s;
}

// The lock's pupil, as the CLI's: the twin camera's scene's, the mask given, else none (the lock
// finds it in its reference frames).
psi::Mask lock_mask(const MeasureArgs& a, const Setup& s) {
  if (s.scene && a.camera == "twin")
    return s.scene->mask;
  if (!a.mask.is_none())
    return mask_from_numpy(a.mask, s.config.camera.settings.width_px,
                           s.config.camera.settings.height_px, "mask");
  return {};
}

py::dict measure(const MeasureArgs& a) {
  Setup s = prepare(a);
  const ps::config::ProjectConfig& project = s.config.installation.project;
  ps::runtime::SimOptions so;
  so.design = project.design;
  so.twin = project.twin;
  so.seed = a.seed;
  so.rate_Hz = a.rate_Hz;
  if (a.config)
    so.source = *a.config;
  ps::runtime::SimBackend sim(so);
  sim.configure();
  ps::runtime::SimulatedClock clock;
  ins::SequenceResult r;
  std::string camera_name;
  psi::Mask pupil = lock_mask(a, s);  // with the GIL: it may read a numpy array
  {
    py::gil_scoped_release release;
    s.calibration = resolve(a, project);
    if (const std::optional<std::string> who =
            ins::lock_requested_by(a.lock, "lock", s.calibration))
      s.params.lock = ins::measurement_lock_setup(std::move(pupil), s.config.camera.pupil_radius_m,
                                                  project.twin.geometry, s.calibration,
                                                  a.lock_retake_s, s.params, *who);
    if (const std::string why =
            ins::travel_problem(s.params, s.calibration.travel_z_max_um, s.calibration.source);
        !why.empty())
      throw ps::core::InputError("measure: " + why);
    std::unique_ptr<cam::Camera> camera =
        open_camera(a, s.config.camera, s.scene ? &*s.scene : nullptr);
    ins::LoopSetup loop;
    loop.controller = s.calibration.params;
    loop.limits = s.config.installation.safety;
    loop.rate_Hz = a.rate_Hz;
    r = ins::acquire_sequence(sim, clock, &sim.twin(), *camera, loop, s.params);
    camera->stop();
    camera_name = camera->name();
  }
  py::dict d = sequence_dict(r, s.params, camera_name, s.calibration, s.algorithm);
  if (!r.validity.valid)
    fail("measure: " + r.validity.reason, d);
  psi::Mask mask;
  if (s.scene) {
    mask = s.scene->mask;
  } else if (!a.mask.is_none()) {
    mask = mask_from_numpy(a.mask, r.frames.front().width_px, r.frames.front().height_px, "mask");
  } else {  // the pupil from the fringe modulation, as `measure` finds it without --mask
    const std::vector<ps::camera::Frame> first(
        r.frames.begin(), r.frames.begin() + static_cast<long>(s.params.steps_rad.size()));
    try {
      mask = psi::pupil_from_modulation(ins::frame_maps(first)).mask;
    } catch (const std::invalid_argument& e) {
      fail(std::string("measure: ") + e.what(), d);
    }
  }
  psi::AnalysisOptions ao;
  ao.phase.algorithm = s.algorithm;
  ao.phase.steps_rad = s.params.steps_rad;
  ao.wavelength_nm = kWavelength_nm;
  ins::MeasurementAnalysis an;
  std::optional<double> error_rms_nm, ideal_rms_nm;
  try {
    py::gil_scoped_release release;
    an = ins::analyze_measurement(r, s.params, mask, ao);
    if (s.scene) {
      error_rms_nm = psi::surface_error_rms_nm(an.surface_nm, s.scene->surface_nm, an.valid);
      ideal_rms_nm = ins::ideal_stage_error_rms_nm(*s.scene, s.config.camera, s.params, ao);
    }
  } catch (const std::invalid_argument& e) {
    fail(std::string("measure: the frames carry no phase: ") + e.what(), d);
  }
  add_analysis(d, an);
  d["truth_nm"] = s.scene ? py::object(map_to_numpy(s.scene->surface_nm)) : py::object(py::none());
  d["mask"] = mask_to_numpy(mask);
  d["error_rms_nm"] = number_or_none(error_rms_nm);
  d["ideal_error_rms_nm"] = number_or_none(ideal_rms_nm);
  if (!an.converged)
    fail("measure: " + an.reason, d);
  return d;
}

// `calibrate --interferometer fizeau --camera twin` (docs/fizeau.md) from Python: the paper's
// three stages with the twin's fringes as the interferometer, the CLI's --json names.
py::dict fringe_calibration(const py::object& config, std::uint64_t seed,
                            const std::string& surface, const std::string& pid) {
  if (pid != "paper" && pid != "search")
    throw ps::core::InputError("calibrate_from_fringes: pid '" + pid +
                               "': expected 'paper' (the paper's gains) or 'search'");
  const cam::InstrumentConfig ic =
      config.is_none() ? cam::InstrumentConfig{} : cam::load_instrument_config(py::str(config));
  const psi::SurfaceSpec spec =
      surface.empty() ? psi::SurfaceSpec{} : psi::parse_surface_spec(surface);
  const ins::FringeCalibrationOptions fo =
      ins::fringe_calibration_options(pid == "search", ic.installation.safety);
  const ps::plant::TwinParams& twin = ic.installation.project.twin;
  ps::rig::check_procedure_budget(
      "calibrate_from_fringes",
      ps::calibration::calibration_cost(fo.stages, twin.daq.sample_time_s), twin,
      ps::plant::kDefaultPhysicsStepBudget, "a twin with fewer physics steps");
  ins::FringeCalibrationOutcome r;
  {
    py::gil_scoped_release release;
    r = ins::calibrate_twin_from_fringes(ic, seed, spec, fo);
  }
  py::dict d;
  d["valid"] = r.validity.valid;
  d["reason"] = r.validity.reason.empty() ? py::object(py::none()) : py::str(r.validity.reason);
  d["controller"] = r.controller;
  const auto& g = r.controller.gains;
  py::dict gains;
  gains["kp"] = g.kp;
  gains["ki"] = g.ki;
  gains["kd"] = g.kd;
  d["pid_gains"] = gains;
  d["A"] = r.controller.matrix.a;
  const auto& p = r.controller.polynomial;
  d["p"] = std::vector<double>{p.p3, p.p2, p.p1, p.p0};
  d["A_rms_residual_um"] = r.matrix.fit.rms_residual_um;
  d["condition_number"] = r.matrix.fit.condition_number;
  d["p_rms_residual_um"] = r.polynomial.fit.rms_residual_um;
  d["p_points"] = r.polynomial.command_um.size();
  d["p_skipped_commands"] = r.polynomial.saturated_points;
  d["frames"] = ins::frames_read(r);
  d["stage2_simulated_s"] = r.stage2_simulated_s;
  d["stage3_simulated_s"] = r.stage3_simulated_s;
  d["wall_s"] = r.wall_time_s;
  if (!r.validity.valid)
    fail("calibrate_from_fringes: " + r.validity.reason, d);
  return d;
}

}  // namespace

void bind_instrument(py::module_& m) {
  const ins::SequenceParams defaults;
  m.def(
      "measure",
      [](const py::object& config, const py::object& calibration, const std::string& camera,
         const std::string& algorithm, const std::vector<double>& steps_rad, int averages,
         const std::string& surface, std::uint64_t seed, double rate_Hz, double base_um,
         double settle_band_nm, double settle_hold_s, double settle_timeout_s,
         double frame_timeout_s, const py::object& mask, const std::string& trigger, bool lock,
         double lock_retake_s, double hold_s) {
        MeasureArgs a;
        if (!config.is_none())
          a.config = py::str(config).cast<std::string>();  // str or os.PathLike
        if (py::isinstance<ps::control::SemiClosedLoopParams>(calibration))
          a.calibration = calibration.cast<ps::control::SemiClosedLoopParams>();
        else if (!calibration.is_none())
          a.calibration = py::str(calibration).cast<std::string>();
        a.camera = camera;
        a.algorithm = algorithm;
        a.steps_rad = steps_rad;
        a.averages = averages;
        a.surface = surface;
        a.seed = seed;
        a.rate_Hz = rate_Hz;
        a.base_um = base_um;
        a.on_target = {settle_band_nm, settle_hold_s, settle_timeout_s};
        a.frame_timeout_s = frame_timeout_s;
        a.mask = mask;
        a.trigger = trigger;
        a.lock = lock;
        a.lock_retake_s = lock_retake_s;
        a.hold_s = hold_s;
        return measure(a);
      },
      py::arg("config") = py::none(), py::arg("calibration") = py::none(),
      py::arg("camera") = "twin", py::arg("algorithm") = "hariharan5",
      py::arg("steps_rad") = std::vector<double>{}, py::arg("averages") = 1,
      py::arg("surface") = "", py::arg("seed") = 1, py::arg("rate_Hz") = 1000.0,
      py::arg("base_um") = defaults.base_um, py::arg("settle_band_nm") = defaults.on_target.band_nm,
      py::arg("settle_hold_s") = defaults.on_target.hold_s,
      py::arg("settle_timeout_s") = defaults.on_target.timeout_s,
      py::arg("frame_timeout_s") = defaults.frame_timeout_s, py::arg("mask") = py::none(),
      py::arg("trigger") = "software", py::arg("lock") = false,
      py::arg("lock_retake_s") = ins::LockSetup{}.retake_s, py::arg("hold_s") = defaults.hold_s,
      "One phase-shifting measurement on the twin (free-running simulated clock), as "
      "`piezoshift measure --daq sim --free-run` takes it; a dict with the names of "
      "`measure --json`, maps and frames as numpy arrays; lock=True holds the cavity on the "
      "fringes, "
      "hold_s holds the stage at frame 0 afterwards (docs/python.md)");
  m.def("calibrate_from_fringes", &fringe_calibration, py::arg("config") = py::none(),
        py::arg("seed") = 1, py::arg("surface") = "", py::arg("pid") = "paper",
        "The paper's calibration on the twin with the Fizeau's fringes as its interferometer, as "
        "`piezoshift calibrate --interferometer fizeau --camera twin --json`: a dict with its "
        "names and `controller`, a SemiClosedLoopParams (docs/fizeau.md); ProcedureFailed when "
        "a scan or a fit fails");
}

}  // namespace piezoshift::python
