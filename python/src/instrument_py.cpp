// Python binding of the instrument module (docs/python.md, "Cameras and measurements"): measure()
// takes one phase-shifting measurement on the twin as `piezoshift measure --daq sim --free-run`
// does, by the same procedure: its arguments become a procedures::MeasureRequest (checked by the
// same validate, refusals naming the argument), procedures::run_measure runs it with the GIL
// released, and the dict is procedures::measure_json's (the CLI's --json) converted, plus the
// maps, frames and the hold's records as numpy arrays. A measurement that is not valid or whose
// fits did not converge raises ProcedureFailed (the CLI's exit status 4), the partial result in
// its `result` attribute. calibrate_from_fringes() encodes with the CLI's
// procedures::fringe_calibration_json.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "images.hpp"
#include "piezoshift/calibration/calibration_cost.hpp"
#include "piezoshift/camera/instrument_config.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/instrument/fringe_calibration.hpp"
#include "piezoshift/instrument/hold_summary.hpp"
#include "piezoshift/plant/simulation_cost.hpp"
#include "piezoshift/procedures/calibration_json.hpp"
#include "piezoshift/procedures/measure_json.hpp"
#include "piezoshift/procedures/measure_run.hpp"
#include "piezoshift/rig/procedure_cost.hpp"
#include "values.hpp"

namespace piezoshift::python {

namespace {

namespace cam = ps::camera;
namespace ins = ps::instrument;
namespace psi = ps::psi;

using ps::procedures::MeasureOutcome;

py::object text_or_none(const std::string& s) {
  return s.empty() ? py::object(py::none()) : py::object(py::str(s));
}

// The hold's records as hold.csv's columns, each an array over the hold's frames.
py::dict hold_records(const ins::SequenceResult& s) {
  const ins::HoldSummary h = ins::hold_summary(s);
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

// The outcome as `measure --json` encodes it (procedures::measure_json), plus what JSON does not
// carry: valid and valid_reason, the frames (a list of arrays in place of their count), the maps,
// the hold's records; a sequence that is not valid keeps its exposures.
py::dict measure_dict(const MeasureOutcome& m) {
  py::dict d = json_to_python(ps::procedures::measure_json(m)).cast<py::dict>();
  const ins::SequenceResult& s = m.sequence;
  d["valid"] = s.validity.valid;
  d["valid_reason"] = text_or_none(s.validity.reason);
  py::list frames;
  for (const cam::Frame& f : s.frames)
    frames.append(counts_to_numpy(f));
  d["frames"] = frames;
  if (!d.contains("exposures"))
    d["exposures"] = json_to_python(ps::procedures::exposures_json(s));
  if (!m.analysis)
    return d;
  d["surface_nm"] = map_to_numpy(m.analysis->surface_nm);
  d["valid_pixels_mask"] = mask_to_numpy(m.analysis->valid);
  d["truth_nm"] = m.truth_nm ? py::object(map_to_numpy(*m.truth_nm)) : py::object(py::none());
  d["mask"] = mask_to_numpy(m.mask);
  if (!s.hold.empty()) {
    py::dict hold = d["hold"].cast<py::dict>();
    hold["records"] = hold_records(s);
  }
  return d;
}

// Raises piezoshift.ProcedureFailed with the partial result attached.
[[noreturn]] void fail(const std::string& why, const py::dict& partial) {
  const py::object type = py::module_::import("piezoshift._piezoshift").attr("ProcedureFailed");
  py::object error = type(why);
  error.attr("result") = partial;
  PyErr_SetObject(type.ptr(), error.ptr());
  throw py::error_already_set();
}

// A (height, width) array of the pupil; its size is checked against the frames' by run_measure.
psi::Mask mask_of_array(const py::object& o) {
  using In = py::array_t<double, py::array::c_style | py::array::forcecast>;
  const In a = o.cast<In>();
  if (a.ndim() != 2)
    throw ps::core::InputError("mask: expected a (height, width) array, the frames' size");
  return mask_from_numpy(o, static_cast<int>(a.shape(1)), static_cast<int>(a.shape(0)), "mask");
}

// `piezoshift measure --daq sim --free-run`: procedures::run_measure, the CLI's own.
py::dict measure(const ps::procedures::MeasureRequest& request) {
  MeasureOutcome m;
  {
    py::gil_scoped_release release;
    m = ps::procedures::run_measure(request);
  }
  py::dict d = measure_dict(m);
  if (m.end != ps::procedures::MeasureEnd::kMeasured)
    fail(m.reason, d);
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
  // The CLI's --json (procedures::fringe_calibration_json), plus valid, reason and the controller.
  py::dict d = json_to_python(ps::procedures::fringe_calibration_json(r)).cast<py::dict>();
  d["valid"] = r.validity.valid;
  d["reason"] = text_or_none(r.validity.reason);
  d["controller"] = r.controller;
  if (!r.validity.valid)
    fail("calibrate_from_fringes: " + r.validity.reason, d);
  return d;
}

}  // namespace

void bind_instrument(py::module_& m) {
  const ps::procedures::MeasureRequest defaults;
  m.def(
      "measure",
      [](const py::object& config, const py::object& calibration, const std::string& camera,
         const std::string& algorithm, const std::vector<double>& steps_rad, int averages,
         const std::string& surface, std::uint64_t seed, double rate_Hz, double base_um,
         double settle_band_nm, double settle_hold_s, double settle_timeout_s,
         double frame_timeout_s, const py::object& mask, const std::string& trigger, bool lock,
         double lock_retake_s, double hold_s) {
        ps::procedures::MeasureRequest q;
        q.caller = ps::procedures::MeasureCaller::kPython;
        q.free_run = true;  // a simulated clock: the twin as fast as the CPU allows
        if (!config.is_none())
          q.config_file = py::str(config).cast<std::string>();  // str or os.PathLike
        if (py::isinstance<ps::control::SemiClosedLoopParams>(calibration))
          q.controller = calibration.cast<ps::control::SemiClosedLoopParams>();
        else if (!calibration.is_none())
          q.calibration_file = py::str(calibration).cast<std::string>();
        q.camera = camera;
        q.algorithm = algorithm;
        q.steps_rad = steps_rad;
        q.averages = averages;
        q.surface = surface;
        q.seed = seed;
        q.rate_Hz = rate_Hz;
        q.base_um = base_um;
        q.on_target = {settle_band_nm, settle_hold_s, settle_timeout_s};
        q.frame_timeout_s = frame_timeout_s;
        if (!mask.is_none())
          q.mask = mask_of_array(mask);
        q.trigger = trigger;
        q.lock = lock;
        q.lock_retake_s = lock_retake_s;
        q.hold_s = hold_s;
        return measure(q);
      },
      py::arg("config") = py::none(), py::arg("calibration") = py::none(),
      py::arg("camera") = "twin", py::arg("algorithm") = "hariharan5",
      py::arg("steps_rad") = std::vector<double>{}, py::arg("averages") = 1,
      py::arg("surface") = "", py::arg("seed") = defaults.seed,
      py::arg("rate_Hz") = defaults.rate_Hz, py::arg("base_um") = defaults.base_um,
      py::arg("settle_band_nm") = defaults.on_target.band_nm,
      py::arg("settle_hold_s") = defaults.on_target.hold_s,
      py::arg("settle_timeout_s") = defaults.on_target.timeout_s,
      py::arg("frame_timeout_s") = defaults.frame_timeout_s, py::arg("mask") = py::none(),
      py::arg("trigger") = "software", py::arg("lock") = false,
      py::arg("lock_retake_s") = defaults.lock_retake_s, py::arg("hold_s") = defaults.hold_s,
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
