// Bindings of the calibration module (docs/calibration.md): the least-squares fits on any data,
// the paper's calibration on the twin and the calibration file.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "piezoshift/calibration/calibration_file.hpp"
#include "piezoshift/calibration/calibration_procedure.hpp"
#include "piezoshift/calibration/matrix_fit.hpp"
#include "piezoshift/calibration/poly_fit.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/runtime/controller_ranges.hpp"
#include "values.hpp"

namespace piezoshift::python {

namespace {

namespace ca = ps::calibration;
using Scl = ps::control::SemiClosedLoopParams;

// Fits on the caller's own data; ill-posed data raises FitError.
void bind_fits(py::module_& m) {
  using Mf = ca::MatrixFitResult;
  py::class_<Mf>(m, "MatrixFitResult")
      .PS_RO(Mf, a)
      .PS_V3(Mf, rms_residual_per_s_um)
      .PS_RO(Mf, rms_residual_um)
      .PS_RO(Mf, condition_number)
      .PS_RO(Mf, design_condition_number)
      .PS_RO(Mf, poses);
  using Pf = ca::PolyFitResult;
  py::class_<Pf>(m, "PolyFitResult")
      .PS_RO(Pf, p)
      .PS_RO(Pf, rms_residual_um)
      .PS_RO(Pf, max_abs_residual_um)
      .PS_RO(Pf, condition_number)
      .PS_RO(Pf, condition_number_unscaled)
      .PS_RO(Pf, points);
  m.def(
      "fit_transmission_matrix",
      [](const InArray& s, const InArray& z, double tol) {
        return ca::fit_transmission_matrix(from_numpy_n3(s, "s_um"), from_numpy_n3(z, "z_um"), tol);
      },
      py::arg("s_um"), py::arg("z_um"), py::arg("rank_rel_tol") = ca::kRankRelTol,
      "Least-squares A of S = A Z from n x 3 arrays of poses (FitError when ill-posed)");
  m.def(
      "fit_cubic_polynomial",
      [](const InArray& measured, const InArray& command, double tol) {
        return ca::fit_cubic_polynomial(from_numpy_1d(measured, "measured_um"),
                                        from_numpy_1d(command, "command_um"), tol);
      },
      py::arg("measured_um"), py::arg("command_um"), py::arg("rank_rel_tol") = ca::kRankRelTol,
      "Least-squares cubic c = p(m) (FitError when ill-posed)");
}

// The procedure's stages (PID gains, A, then p), their options and results.
void bind_stages(py::module_& m) {
  py::enum_<ca::PidChoice>(m, "PidChoice")
      .value("PAPER", ca::PidChoice::kPaper)
      .value("SEARCH", ca::PidChoice::kSearch);
  using Ps = ca::PidScore;
  py::class_<Ps>(m, "PidScore")
      .PS_RO(Ps, overshoot_pct)
      .PS_RO(Ps, settling_time_s)
      .PS_RO(Ps, steady_state_error_nm);
  using Pt = ca::PidTrial;
  py::class_<Pt>(m, "PidTrial")
      .PS_RO(Pt, gains)
      .def_property_readonly(
          "per_actuator",
          [](const Pt& t) { return std::vector<Ps>(t.per_actuator.begin(), t.per_actuator.end()); })
      .PS_RO(Pt, worst)
      .PS_RO(Pt, plate_overshoot_pct)
      .PS_RO(Pt, faulted)
      .PS_RO(Pt, acceptable)
      .PS_RO(Pt, simulated_time_s);
  using PtO = ca::PidTuningOptions;
  py::class_<PtO>(m, "PidTuningOptions")
      .def(py::init<>())
      .PS_SERIES(PtO, kp_values)
      .PS_SERIES(PtO, ki_values)
      .PS_SERIES(PtO, kd_values)
      .PS_RW(PtO, step_fraction)
      .PS_RW(PtO, step_duration_s)
      .PS_RW(PtO, settle_band_pct)
      .PS_RW(PtO, steady_window_s)
      .PS_RW(PtO, max_overshoot_pct)
      .PS_RW(PtO, max_steady_state_error_nm);
  using PtR = ca::PidTuningResult;
  py::class_<PtR>(m, "PidTuningResult")
      .PS_V3(PtR, step_target_um)
      .PS_RO(PtR, best)
      .PS_RO(PtR, paper)
      .PS_RO(PtR, trials)
      .PS_RO(PtR, simulated_time_s);
  using MiO = ca::MatrixIdentificationOptions;
  py::class_<MiO>(m, "MatrixIdentificationOptions")
      .def(py::init<>())
      .PS_RW(MiO, base_um)
      .PS_RW(MiO, move_um)
      .PS_RW(MiO, repeats)
      .PS_RW(MiO, settle_s);
  using MiR = ca::MatrixIdentificationResult;
  py::class_<MiR>(m, "MatrixIdentificationResult")
      .PS_RO(MiR, fit)
      .def_property_readonly("ds_um", [](const MiR& r) { return to_numpy(r.ds_um); })
      .def_property_readonly("dz_um", [](const MiR& r) { return to_numpy(r.dz_um); })
      .PS_RO(MiR, simulated_time_s);
  using PiO = ca::PolynomialIdentificationOptions;
  py::class_<PiO>(m, "PolynomialIdentificationOptions")
      .def(py::init<>())
      .PS_RW(PiO, points)
      .PS_RW(PiO, max_um)
      .PS_RW(PiO, settle_s);
  using PiR = ca::PolynomialIdentificationResult;
  py::class_<PiR>(m, "PolynomialIdentificationResult")
      .PS_RO(PiR, fit)
      .PS_SERIES(PiR, command_um)
      .PS_SERIES(PiR, measured_um)
      .PS_RO(PiR, saturated_points)
      .PS_RO(PiR, simulated_time_s);
}

void bind_procedure(py::module_& m) {
  using CaO = ca::CalibrationOptions;
  py::class_<CaO>(m, "CalibrationOptions")
      .def(py::init<>())
      .PS_RW(CaO, pid)
      .PS_RW(CaO, pid_tuning)
      .PS_RW(CaO, matrix)
      .PS_RW(CaO, polynomial);
  using CaR = ca::CalibrationOutcome;
  py::class_<CaR>(m, "CalibrationOutcome")
      .PS_RO(CaR, controller)
      .PS_RO(CaR, pid)
      .PS_RO(CaR, matrix)
      .PS_RO(CaR, polynomial);
  m.def(
      "calibrate",
      [](const ps::config::ProjectConfig& c, const Scl& base, std::uint64_t seed, const CaO& o) {
        py::gil_scoped_release nogil;
        return ca::calibrate(c, base, seed, o);
      },
      py::arg("config"), py::arg("base"), py::arg("seed"),
      py::arg_v("options", CaO{}, "CalibrationOptions()"),
      "The paper's calibration on the twin: PID gains, A, then p (Section 3)");
}

// What `piezoshift calibrate --out` writes and `serve`/`run --calibration` read.
void bind_calibration_file(py::module_& m) {
  m.def(
      "controller_problem",
      [](const Scl& params, std::optional<double> loop_sample_time_s) {
        return ps::runtime::controller_problem(
            params, loop_sample_time_s.value_or(ps::runtime::own_sample_time_s(params)));
      },
      py::arg("params"), py::arg("loop_sample_time_s") = py::none(),
      "The first problem of params as a calibration, naming the field (each number's range, p "
      "rising over the stroke, A finite, normal and well conditioned, PIDs stable on the nominal "
      "inner loop, what the loop itself refuses; runtime/controller_ranges.hpp); '' when "
      "none. loop_sample_time_s: the loop's period (default: the rate the set was made for). "
      "load_calibration_file refuses a file this finds a problem in.");
  m.def(
      "load_calibration_file",
      [](const std::string& path) {
        std::optional<double> z_max_um;
        const Scl params = ps::calibration::load_calibration_file(path, &z_max_um);
        return py::make_tuple(params, z_max_um ? py::cast(*z_max_um) : py::none());
      },
      py::arg("path"),
      "A calibration file (`piezoshift calibrate --out`) -> (SemiClosedLoopParams, travel z_max_um "
      "or None); raises InputError naming file, key and reason");
  m.def(
      "write_calibration_file",
      [](const std::string& path, const Scl& params, const std::string& header,
         std::optional<double> z_max_um) {
        ps::calibration::write_calibration_file(path, params, header, z_max_um);
      },
      py::arg("path"), py::arg("params"), py::arg("header") = "written by piezoshift (Python)",
      py::arg("z_max_um") = py::none(),
      "Writes params (gains, p, A, scaling) and the travel as `piezoshift serve` and `run` read "
      "them; atomically");
  m.def(
      "format_calibration",
      [](const Scl& params, const std::string& header, std::optional<double> z_max_um) {
        return ps::calibration::format_calibration(params, header, z_max_um);
      },
      py::arg("params"), py::arg("header") = "written by piezoshift (Python)",
      py::arg("z_max_um") = py::none(), "The calibration file's text");
}

}  // namespace

void bind_calibration(py::module_& m) {
  bind_fits(m);
  bind_stages(m);
  bind_procedure(m);
  bind_calibration_file(m);
}

}  // namespace piezoshift::python
