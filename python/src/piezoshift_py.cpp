// Python bindings of piezoshift's offline API (docs/python.md): design, configuration, the digital
// twin, the bench, the paper's experiments, calibration, the fits, the metrics and reproduce().
// Value structs become Python classes with the same field names (nested structs are returned by
// reference, so cfg.design.hinge.thickness_m = ... edits in place). Three-channel values (Vec3)
// and 3x3 matrices come back as numpy copies and are set by assigning a whole value; time series
// (std::vector<double>) come back as 1-D numpy arrays. io::InputError becomes
// piezoshift.InputError (a ValueError); calibration::FitError and experiments::MetricsError
// piezoshift.FitError and piezoshift.MetricsError (both InputErrors);
// std::invalid_argument ValueError, all with the C++ message. The real-time runtime is not bound.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "piezoshift/calibration/calibration_file.hpp"
#include "piezoshift/calibration/calibration_procedure.hpp"
#include "piezoshift/calibration/fit_error.hpp"
#include "piezoshift/calibration/matrix_fit.hpp"
#include "piezoshift/calibration/poly_fit.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/design/design_evaluation.hpp"
#include "piezoshift/design/design_inputs.hpp"
#include "piezoshift/design/flexure.hpp"
#include "piezoshift/design/hinge_search.hpp"
#include "piezoshift/experiments/bench.hpp"
#include "piezoshift/experiments/metrics_error.hpp"
#include "piezoshift/experiments/metrics_linearity.hpp"
#include "piezoshift/experiments/metrics_repeatability.hpp"
#include "piezoshift/experiments/metrics_step_response.hpp"
#include "piezoshift/experiments/paper_experiments.hpp"
#include "piezoshift/io/input_error.hpp"
#include "piezoshift/plant/twin.hpp"
#include "piezoshift/plant/twin_params.hpp"
#include "piezoshift/reproduction/report.hpp"
#include "piezoshift/reproduction/reproduction.hpp"
#include "piezoshift/reproduction/summary.hpp"
#include "piezoshift/runtime/safety_ranges.hpp"
#include "values.hpp"

namespace py = pybind11;
namespace ps = piezoshift;
using piezoshift::python::Array;
using piezoshift::python::from_numpy_1d;
using piezoshift::python::from_numpy_n3;
using piezoshift::python::to_numpy;
using Scl = ps::control::SemiClosedLoopParams;
using ps::control::Mat3;
using ps::control::Vec3;

namespace {

py::object json_to_python(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

}  // namespace

void bind_psi(py::module_& m);  // psi_py.cpp
namespace piezoshift::python {
void bind_control(py::module_& m);  // control_py.cpp
}

PYBIND11_MODULE(_piezoshift, m) {
  m.doc() = "piezoshift: design, digital twin, calibration and experiments (offline API)";

  // Errors. InputError derives from ValueError so `except ValueError` catches bad input too.
  static py::exception<ps::io::InputError> input_error(m, "InputError", PyExc_ValueError);
  static py::exception<ps::calibration::FitError> fit_error(m, "FitError", input_error.ptr());
  static py::exception<ps::experiments::MetricsError> metrics_error(m, "MetricsError",
                                                                    input_error.ptr());
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p)
        std::rethrow_exception(p);
    } catch (const ps::calibration::FitError& e) {
      fit_error(e.what());
    } catch (const ps::experiments::MetricsError& e) {
      metrics_error(e.what());
    } catch (const ps::io::InputError& e) {
      input_error(e.what());
    }
  });
  bind_psi(m);

  piezoshift::python::bind_control(m);

  // ---- design ---------------------------------------------------------------------------
  namespace d = ps::design;
  py::class_<d::ActuatorParams>(m, "ActuatorParams")
      .def(py::init<>())
      .PS_RW(d::ActuatorParams, stiffness_N_per_um)
      .PS_RW(d::ActuatorParams, nominal_stroke_um)
      .PS_RW(d::ActuatorParams, pushing_force_N)
      .PS_RW(d::ActuatorParams, pulling_force_N)
      .PS_RW(d::ActuatorParams, capacitance_F)
      .PS_RW(d::ActuatorParams, resonance_frequency_Hz)
      .PS_RW(d::ActuatorParams, length_m);
  py::class_<d::MaterialParams>(m, "MaterialParams")
      .def(py::init<>())
      .PS_RW(d::MaterialParams, elastic_modulus_Pa)
      .PS_RW(d::MaterialParams, poisson_ratio)
      .PS_RW(d::MaterialParams, density_kg_per_m3)
      .PS_RW(d::MaterialParams, allowable_stress_Pa);
  py::class_<d::HingeParams>(m, "HingeParams")
      .def(py::init<>())
      .PS_RW(d::HingeParams, width_m)
      .PS_RW(d::HingeParams, thickness_m)
      .PS_RW(d::HingeParams, radius_m)
      .PS_RW(d::HingeParams, link_length_m);
  py::class_<d::MechanismParams>(m, "MechanismParams")
      .def(py::init<>())
      .PS_RW(d::MechanismParams, moving_mass_kg);
  py::class_<d::DesignInputs>(m, "DesignInputs")
      .def(py::init<>())
      .PS_RW(d::DesignInputs, actuator)
      .PS_RW(d::DesignInputs, material)
      .PS_RW(d::DesignInputs, hinge)
      .PS_RW(d::DesignInputs, mechanism)
      .def(
          "problem", [](const d::DesignInputs& in) { return d::design_inputs_problem(in); },
          "Why the inputs are not physical, or '' when they are");

  using Ev = d::DesignEvaluation;
  py::class_<Ev>(m, "DesignEvaluation")
      .PS_RO(Ev, hinge_angular_stiffness_Nm_per_rad)
      .PS_RO(Ev, mechanism_stiffness_N_per_um)
      .PS_RO(Ev, stiffness_rule_limit_N_per_um)
      .PS_RO(Ev, stiffness_ratio)
      .PS_RO(Ev, rule_ka_over_10_ok)
      .PS_RO(Ev, available_displacement_um)
      .PS_RO(Ev, stroke_loss_percent)
      .PS_RO(Ev, spring_force_at_stroke_N)
      .PS_RO(Ev, force_within_pushing_limit)
      .PS_RO(Ev, hinge_rotation_at_stroke_rad)
      .PS_RO(Ev, hinge_moment_at_stroke_Nm)
      .PS_RO(Ev, stress_concentration_factor)
      .PS_RO(Ev, nominal_stress_at_stroke_Pa)
      .PS_RO(Ev, max_stress_at_stroke_Pa)
      .PS_RO(Ev, allowable_stress_Pa)
      .PS_RO(Ev, stress_margin)
      .PS_RO(Ev, stress_ok)
      .PS_RO(Ev, natural_frequency_Hz)
      .PS_RO(Ev, thickness_to_radius);

  m.def("evaluate_design", &d::evaluate_design, py::arg("inputs"),
        "The design report of Eqs. 1 to 4, stress and natural frequency (ValueError when the "
        "inputs are not physical)");
  m.def("hinge_angular_stiffness_Nm_per_rad", &d::hinge_angular_stiffness_Nm_per_rad,
        py::arg("material"), py::arg("hinge"), "Eq. 2");
  m.def("mechanism_stiffness_N_per_um", &d::mechanism_stiffness_N_per_um, py::arg("material"),
        py::arg("hinge"), "Eq. 3");
  m.def("available_displacement_um", &d::available_displacement_um, py::arg("actuator"),
        py::arg("mechanism_stiffness_N_per_um"), "Eq. 1");

  // ---- twin parameters --------------------------------------------------------------------
  namespace pl = ps::plant;
  py::class_<pl::DaqParams>(m, "DaqParams")
      .def(py::init<>())
      .PS_RW(pl::DaqParams, sample_time_s)
      .PS_RW(pl::DaqParams, range_V)
      .PS_RW(pl::DaqParams, resolution_bits)
      .PS_RW(pl::DaqParams, ai_noise_V_rms);
  py::class_<pl::AmplifierParams>(m, "AmplifierParams")
      .def(py::init<>())
      .PS_RW(pl::AmplifierParams, gain)
      .PS_RW(pl::AmplifierParams, output_min_V)
      .PS_RW(pl::AmplifierParams, output_max_V)
      .PS_RW(pl::AmplifierParams, average_power_W)
      .PS_RW(pl::AmplifierParams, small_signal_bandwidth_Hz);
  py::class_<pl::HysteresisParams>(m, "HysteresisParams")
      .def(py::init<>())
      .PS_RW(pl::HysteresisParams, hysteresis_fraction)
      .PS_RW(pl::HysteresisParams, play_operators);
  py::class_<pl::CreepParams>(m, "CreepParams")
      .def(py::init<>())
      .PS_RW(pl::CreepParams, per_decade_fraction)
      .PS_RW(pl::CreepParams, shortest_time_constant_s)
      .PS_RW(pl::CreepParams, longest_time_constant_s)
      .PS_RW(pl::CreepParams, terms_per_decade);
  py::class_<pl::PiezoParams>(m, "PiezoParams")
      .def(py::init<>())
      .PS_RW(pl::PiezoParams, hysteresis)
      .PS_RW(pl::PiezoParams, creep)
      .PS_RW(pl::PiezoParams, creep_reference_time_s)
      .PS_V3(pl::PiezoParams, free_stroke_scale);
  py::class_<pl::ContactParams>(m, "ContactParams")
      .def(py::init<>())
      .PS_RW(pl::ContactParams, open_loop_travel_um)
      .PS_RW(pl::ContactParams, open_loop_time_s)
      .PS_RW(pl::ContactParams, stiffness_N_per_um)
      .PS_RW(pl::ContactParams, ball_radius_m)
      .PS_RW(pl::ContactParams, preload_N);
  py::class_<pl::MechanicsParams>(m, "MechanicsParams")
      .def(py::init<>())
      .PS_RW(pl::MechanicsParams, mechanism_damping_ratio)
      .PS_RW(pl::MechanicsParams, modal_damping_ratio);
  py::class_<pl::PlateParams>(m, "PlateParams")
      .def(py::init<>())
      .PS_RW(pl::PlateParams, radius_m)
      .PS_RW(pl::PlateParams, thickness_m)
      .PS_RW(pl::PlateParams, payload_mass_kg);
  py::class_<pl::GeometryParams>(m, "GeometryParams")
      .def(py::init<>())
      .PS_RW(pl::GeometryParams, actuator_radius_m)
      .PS_RW(pl::GeometryParams, first_actuator_angle_deg)
      .PS_V3(pl::GeometryParams, transmission_matrix)
      .PS_V3(pl::GeometryParams, height_errors_um);
  py::enum_<pl::SgsNonlinearityShape>(m, "SgsNonlinearityShape")
      .value("BOW", pl::SgsNonlinearityShape::kBow)
      .value("S_CURVE", pl::SgsNonlinearityShape::kSCurve)
      .value("WAVE", pl::SgsNonlinearityShape::kWave);
  py::class_<pl::SgsParams>(m, "SgsParams")
      .def(py::init<>())
      .PS_RW(pl::SgsParams, full_scale_V)
      .PS_RW(pl::SgsParams, nonlinearity_fraction)
      .PS_RW(pl::SgsParams, nonlinearity_shape)
      .PS_RW(pl::SgsParams, noise_nm_rms)
      .PS_RW(pl::SgsParams, bandwidth_Hz)
      .PS_V3(pl::SgsParams, offset_V)
      .PS_RW(pl::SgsParams, zero_drift_nm_per_K)
      .PS_RW(pl::SgsParams, gauge_creep_fraction)
      .PS_RW(pl::SgsParams, gauge_creep_time_s)
      .PS_RW(pl::SgsParams, flicker_corner_Hz)
      .PS_RW(pl::SgsParams, excitation_drift_ppm_rms)
      .PS_RW(pl::SgsParams, excitation_drift_window_s);
  py::class_<pl::InterferometerParams>(m, "InterferometerParams")
      .def(py::init<>())
      .PS_RW(pl::InterferometerParams, wavelength_nm)
      .PS_RW(pl::InterferometerParams, resolution_nm)
      .PS_RW(pl::InterferometerParams, accuracy_ppm)
      .PS_RW(pl::InterferometerParams, noise_nm_rms)
      .PS_RW(pl::InterferometerParams, cyclic_error_nm)
      .PS_RW(pl::InterferometerParams, dynamic_sample_rate_Hz)
      .PS_RW(pl::InterferometerParams, static_average_s);
  py::class_<pl::LabParams>(m, "LabParams")
      .def(py::init<>())
      .PS_RW(pl::LabParams, temperature_C)
      .PS_RW(pl::LabParams, temperature_rms_K)
      .PS_RW(pl::LabParams, temperature_correlation_time_s)
      .PS_RW(pl::LabParams, structure_time_constant_s)
      .PS_RW(pl::LabParams, metrology_loop_length_m)
      .PS_RW(pl::LabParams, metrology_loop_cte_per_K)
      .PS_RW(pl::LabParams, dead_path_m)
      .PS_RW(pl::LabParams, air_index_per_K);
  py::class_<pl::TwinParams>(m, "TwinParams")
      .def(py::init<>())
      .PS_RW(pl::TwinParams, physics_rate_Hz)
      .PS_RW(pl::TwinParams, daq)
      .PS_RW(pl::TwinParams, amplifier)
      .PS_RW(pl::TwinParams, piezo)
      .PS_RW(pl::TwinParams, contact)
      .PS_RW(pl::TwinParams, mechanics)
      .PS_RW(pl::TwinParams, plate)
      .PS_RW(pl::TwinParams, geometry)
      .PS_RW(pl::TwinParams, sgs)
      .PS_RW(pl::TwinParams, interferometer)
      .PS_RW(pl::TwinParams, lab);
  m.def("twin_params_problem", &pl::twin_params_problem, py::arg("design"), py::arg("twin"),
        "Why design and twin parameters cannot make a twin, or '' when they can");

  // ---- configuration ----------------------------------------------------------------------
  py::class_<ps::config::ProjectConfig>(m, "ProjectConfig")
      .def(py::init<>())
      .PS_RW(ps::config::ProjectConfig, design)
      .PS_RW(ps::config::ProjectConfig, twin);
  // An installation's file may carry [safety] (runtime/safety_ranges.hpp): read and checked here
  // too, so that the same file loads in Python and in the CLI.
  m.def(
      "load_project_config",
      [](const std::string& path) { return ps::runtime::load_installation_config(path).project; },
      py::arg("path"), "Loads a TOML configuration (InputError naming file, key and reason)");

  // ---- twin -------------------------------------------------------------------------------
  py::enum_<pl::AoStatus>(m, "AoStatus")
      .value("OK", pl::AoStatus::kOk)
      .value("CLAMPED", pl::AoStatus::kClamped)
      .value("INVALID", pl::AoStatus::kInvalid);

  using Tr = pl::TwinTruth;
  py::class_<Tr>(m, "TwinTruth")
      .PS_RO(Tr, time_s)
      .PS_V3(Tr, ao_V)
      .PS_V3(Tr, amplifier_V)
      .PS_V3(Tr, free_elongation_um)
      .PS_V3(Tr, stack_elongation_um)
      .PS_V3(Tr, leg_um)
      .PS_RO(Tr, plate_z_um)
      .PS_RO(Tr, theta_x_urad)
      .PS_RO(Tr, theta_y_urad)
      .PS_V3(Tr, points_um)
      .PS_V3(Tr, sgs_V)
      .PS_RO(Tr, air_temperature_C)
      .PS_RO(Tr, structure_temperature_C)
      .PS_RO(Tr, sgs_excitation_drift_ppm)
      .PS_V3(Tr, sgs_zero_flicker_nm)
      .PS_V3(Tr, gauge_creep_um)
      .PS_RO(Tr, interferometer_drift_nm);

  using Ifm = pl::InterferometerReading;
  py::class_<Ifm>(m, "InterferometerReading")
      .PS_V3(Ifm, dynamic_um)
      .PS_RO(Ifm, dynamic_time_s)
      .PS_V3(Ifm, static_um)
      .PS_RO(Ifm, static_time_s)
      .PS_RO(Ifm, static_count);

  using Cf = pl::ChannelFault;
  py::class_<Cf>(m, "ChannelFault")
      .def(py::init<>())
      .PS_RW(Cf, amplifier_failed)
      .PS_RW(Cf, sgs_open)
      .PS_RW(Cf, sgs_stuck)
      .PS_RW(Cf, adc_nan)
      .PS_RW(Cf, adc_spike_V)
      .PS_RW(Cf, stack_stiffness_scale);

  // Truth and readings are returned as copies: they change at every step.
  py::class_<pl::Twin>(m, "Twin")
      .def(py::init<const d::DesignInputs&, const pl::TwinParams&, std::uint64_t>(),
           py::arg("design"), py::arg("params"), py::arg("seed"))
      .def(py::init([](const ps::config::ProjectConfig& c, std::uint64_t seed) {
             return pl::Twin(c.design, c.twin, seed);
           }),
           py::arg("config"), py::arg("seed"))
      .def("write_ao", &pl::Twin::write_ao, py::arg("ao_V"))
      .def("advance", &pl::Twin::advance)
      .def("read_ai", [](const pl::Twin& t) { return to_numpy(t.read_ai()); })
      .def(
          "step", [](pl::Twin& t, const Vec3& v) { return to_numpy(t.step(v)); }, py::arg("ao_V"))
      .def(
          "run",
          [](pl::Twin& t, const Vec3& ao_V, std::size_t ticks) {
            // Holds ao_V for `ticks` periods; returns the AI samples and the true points.
            Array ai({static_cast<py::ssize_t>(ticks), py::ssize_t{3}});
            Array pts({static_cast<py::ssize_t>(ticks), py::ssize_t{3}});
            auto a = ai.mutable_unchecked<2>();
            auto p = pts.mutable_unchecked<2>();
            t.write_ao(ao_V);
            for (std::size_t k = 0; k < ticks; ++k) {
              t.advance();
              const auto kk = static_cast<py::ssize_t>(k);
              for (py::ssize_t j = 0; j < 3; ++j) {
                a(kk, j) = t.read_ai()[j];
                p(kk, j) = t.truth().points_um[j];
              }
            }
            return py::make_tuple(ai, pts);
          },
          py::arg("ao_V"), py::arg("ticks"),
          "Holds ao_V for `ticks` control periods; returns (ai_V, points_um), each ticks x 3")
      .def("truth", [](const pl::Twin& t) { return t.truth(); })
      .def("interferometer", [](const pl::Twin& t) { return t.interferometer(); })
      .def_property_readonly("time_s", &pl::Twin::time_s)
      .def_property_readonly("ticks", &pl::Twin::ticks)
      .def_property_readonly("seed", &pl::Twin::seed)
      .def("set_fault", &pl::Twin::set_fault, py::arg("channel"), py::arg("fault"))
      .def("fault", &pl::Twin::fault, py::arg("channel"));

  // ---- bench and experiments --------------------------------------------------------------
  namespace ex = ps::experiments;
  py::enum_<ex::DriveMode>(m, "DriveMode")
      .value("OPEN_LOOP", ex::DriveMode::kOpenLoop)
      .value("ACTUATORS", ex::DriveMode::kActuators)
      .value("POINTS", ex::DriveMode::kPoints);
  using Sm = ex::StaticMeasurement;
  py::class_<Sm>(m, "StaticMeasurement")
      .PS_V3(Sm, points_um)
      .PS_V3(Sm, sgs_um)
      .PS_RO(Sm, window_end_s);

  py::class_<ex::Bench>(m, "Bench")
      .def(py::init<const ps::config::ProjectConfig&, const Scl&, std::uint64_t>(),
           py::arg("config"), py::arg("controller"), py::arg("seed"))
      .def("set_controller", &ex::Bench::set_controller, py::arg("params"))
      .def("controller_params", &ex::Bench::controller_params)
      .def("drive_open_loop", &ex::Bench::drive_open_loop, py::arg("ao_V"))
      .def("drive_actuators", &ex::Bench::drive_actuators, py::arg("target_um"))
      .def("drive_points", &ex::Bench::drive_points, py::arg("zd_um"))
      .def(
          "run", [](ex::Bench& b, double duration_s) { b.run(duration_s); }, py::arg("duration_s"))
      .def(
          "record",
          [](ex::Bench& b, double duration_s) {
            // run() with every tick's time, true mean of P1..P3 and SGS feedback kept.
            std::vector<double> t, z, fb;
            b.run(duration_s, [&](const ex::Bench& bb) {
              const auto& p = bb.twin().truth().points_um;
              t.push_back(bb.time_s());
              z.push_back((p[0] + p[1] + p[2]) / 3.0);
              const auto& f = bb.last_output().feedback_um;
              fb.push_back((f[0] + f[1] + f[2]) / 3.0);
            });
            py::dict d;
            d["time_s"] = to_numpy(t);
            d["mean_points_um"] = to_numpy(z);
            d["mean_feedback_um"] = to_numpy(fb);
            return d;
          },
          py::arg("duration_s"),
          "run() recording per tick: time_s, true mean of P1..P3 and mean SGS feedback [um]")
      .def("measure_static", &ex::Bench::measure_static)
      .def_property_readonly("twin", &ex::Bench::twin, py::return_value_policy::reference_internal)
      .def("last_output", &ex::Bench::last_output)
      .def_property_readonly("mode", &ex::Bench::mode)
      .def_property_readonly("time_s", &ex::Bench::time_s)
      .def_property_readonly("sample_time_s", &ex::Bench::sample_time_s)
      .def_property_readonly("ticks", &ex::Bench::ticks);

  // metrics
  using SrO = ex::StepResponseOptions;
  py::class_<SrO>(m, "StepResponseOptions")
      .def(py::init<>())
      .PS_RW(SrO, step_time_s)
      .PS_RW(SrO, initial_um)
      .PS_RW(SrO, final_um)
      .PS_RW(SrO, final_window_fraction)
      .PS_RW(SrO, band_pct)
      .PS_RW(SrO, band_nm)
      .PS_RW(SrO, median_window);
  using SrM = ex::StepResponseMetrics;
  py::class_<SrM>(m, "StepResponseMetrics")
      .PS_RO(SrM, initial_um)
      .PS_RO(SrM, final_um)
      .PS_RO(SrM, step_um)
      .PS_RO(SrM, t10_s)
      .PS_RO(SrM, t90_s)
      .PS_RO(SrM, rise_time_s)
      .PS_RO(SrM, peak_um)
      .PS_RO(SrM, peak_time_s)
      .PS_RO(SrM, overshoot_pct)
      .PS_RO(SrM, settling_time_pct_s)
      .PS_RO(SrM, settling_time_abs_s)
      .PS_RO(SrM, band_pct)
      .PS_RO(SrM, band_nm);
  using LiM = ex::LinearityMetrics;
  py::class_<LiM>(m, "LinearityMetrics")
      .PS_RO(LiM, n)
      .PS_RO(LiM, span_um)
      .PS_RO(LiM, zero_end_slope)
      .PS_RO(LiM, zero_end_intercept_um)
      .PS_RO(LiM, best_fit_slope)
      .PS_RO(LiM, best_fit_intercept_um)
      .PS_RO(LiM, max_deviation_zero_end_um)
      .PS_RO(LiM, max_deviation_best_fit_um)
      .PS_RO(LiM, linearity_zero_end_pct)
      .PS_RO(LiM, linearity_best_fit_pct)
      .PS_SERIES(LiM, deviation_zero_end_um)
      .PS_SERIES(LiM, deviation_best_fit_um);
  using ReM = ex::RepeatabilityMetrics;
  py::class_<ReM>(m, "RepeatabilityMetrics")
      .PS_RO(ReM, n)
      .PS_RO(ReM, mean_um)
      .PS_RO(ReM, repeatability_um)
      .PS_RO(ReM, repeatability_nm)
      .PS_RO(ReM, min_um)
      .PS_RO(ReM, max_um);

  using In = py::array_t<double, py::array::c_style | py::array::forcecast>;
  m.def(
      "step_response_metrics",
      [](const In& t, const In& y, const SrO& o) {
        const auto tv = from_numpy_1d(t, "t_s");
        const auto yv = from_numpy_1d(y, "y_um");
        return ex::step_response_metrics(tv, yv, o);
      },
      py::arg("t_s"), py::arg("y_um"), py::arg_v("options", SrO{}, "StepResponseOptions()"));
  m.def(
      "running_median",
      [](const In& y, std::size_t window) {
        return to_numpy(ex::running_median(from_numpy_1d(y, "y"), window));
      },
      py::arg("y"), py::arg("window"));
  m.def(
      "linearity_metrics",
      [](const In& desired, const In& measured) {
        return ex::linearity_metrics(from_numpy_1d(desired, "desired_um"),
                                     from_numpy_1d(measured, "measured_um"));
      },
      py::arg("desired_um"), py::arg("measured_um"));
  m.def(
      "repeatability_metrics",
      [](const In& measured) {
        return ex::repeatability_metrics(from_numpy_1d(measured, "measured_um"));
      },
      py::arg("measured_um"));

  // experiments
  using TrO = ex::TravelRangeOptions;
  py::class_<TrO>(m, "TravelRangeOptions")
      .def(py::init<>())
      .PS_RW(TrO, open_loop_settle_s)
      .PS_RW(TrO, start_um)
      .PS_RW(TrO, increment_um)
      .PS_RW(TrO, max_um)
      .PS_RW(TrO, hold_s)
      .PS_RW(TrO, tolerance_um);
  using TrR = ex::TravelRangeResult;
  py::class_<TrR>(m, "TravelRangeResult")
      .PS_RO(TrR, open_loop_um)
      .PS_V3(TrR, open_loop_points_um)
      .PS_RO(TrR, semi_closed_um)
      .PS_SERIES(TrR, desired_um)
      .PS_SERIES(TrR, measured_um)
      .def_property_readonly("saturated_mask",
                             [](const TrR& r) {
                               return py::array_t<int>(
                                   static_cast<py::ssize_t>(r.saturated_mask.size()),
                                   r.saturated_mask.data());
                             })
      .PS_RO(TrR, simulated_time_s);
  using StO = ex::StepExperimentOptions;
  py::class_<StO>(m, "StepExperimentOptions")
      .def(py::init<>())
      .PS_RW(StO, step_um)
      .PS_RW(StO, pre_s)
      .PS_RW(StO, record_s)
      .PS_RW(StO, band_pct)
      .PS_RW(StO, band_nm);
  using StR = ex::StepExperimentResult;
  py::class_<StR>(m, "StepExperimentResult")
      .PS_SERIES(StR, time_s)
      .PS_SERIES(StR, measured_um)
      .PS_SERIES(StR, desired_um)
      .PS_RO(StR, metrics)
      .PS_RO(StR, simulated_time_s);
  using LiO = ex::LinearityOptions;
  py::class_<LiO>(m, "LinearityOptions")
      .def(py::init<>())
      .PS_RW(LiO, max_um)
      .PS_RW(LiO, increment_um)
      .PS_RW(LiO, step_hold_s)
      .PS_RW(LiO, skip_samples);
  using LiR = ex::LinearityResult;
  py::class_<LiR>(m, "LinearityResult")
      .PS_SERIES(LiR, desired_um)
      .PS_SERIES(LiR, measured_um)
      .PS_SERIES(LiR, sample_time_s)
      .PS_SERIES(LiR, sample_desired_um)
      .PS_SERIES(LiR, sample_measured_um)
      .PS_RO(LiR, metrics)
      .PS_RO(LiR, simulated_time_s);
  using RpO = ex::RepeatabilityOptions;
  py::class_<RpO>(m, "RepeatabilityOptions")
      .def(py::init<>())
      .PS_RW(RpO, target_um)
      .PS_RW(RpO, moves)
      .PS_RW(RpO, rest_s)
      .PS_RW(RpO, settle_s);
  using RpR = ex::RepeatabilityResult;
  py::class_<RpR>(m, "RepeatabilityResult")
      .PS_RO(RpR, target_um)
      .PS_SERIES(RpR, measured_um)
      .PS_RO(RpR, metrics)
      .PS_RO(RpR, simulated_time_s);

  // The experiments run with the GIL released: they touch no Python object.
  m.def(
      "run_travel_range",
      [](const ps::config::ProjectConfig& c, const Scl& p, std::uint64_t seed, const TrO& o) {
        py::gil_scoped_release nogil;
        return ex::run_travel_range(c, p, seed, o);
      },
      py::arg("config"), py::arg("controller"), py::arg("seed"),
      py::arg_v("options", TrO{}, "TravelRangeOptions()"));
  m.def(
      "run_step_response",
      [](const ps::config::ProjectConfig& c, const Scl& p, std::uint64_t seed, const StO& o) {
        py::gil_scoped_release nogil;
        return ex::run_step_response(c, p, seed, o);
      },
      py::arg("config"), py::arg("controller"), py::arg("seed"),
      py::arg_v("options", StO{}, "StepExperimentOptions()"));
  m.def(
      "run_linearity",
      [](const ps::config::ProjectConfig& c, const Scl& p, std::uint64_t seed, const LiO& o) {
        py::gil_scoped_release nogil;
        return ex::run_linearity(c, p, seed, o);
      },
      py::arg("config"), py::arg("controller"), py::arg("seed"),
      py::arg_v("options", LiO{}, "LinearityOptions()"));
  m.def(
      "run_repeatability",
      [](const ps::config::ProjectConfig& c, const Scl& p, std::uint64_t seed, const RpO& o) {
        py::gil_scoped_release nogil;
        return ex::run_repeatability(c, p, seed, o);
      },
      py::arg("config"), py::arg("controller"), py::arg("seed"),
      py::arg_v("options", RpO{}, "RepeatabilityOptions()"));

  // ---- calibration --------------------------------------------------------------------------
  namespace ca = ps::calibration;
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
      [](const In& s, const In& z, double tol) {
        return ca::fit_transmission_matrix(from_numpy_n3(s, "s_um"), from_numpy_n3(z, "z_um"), tol);
      },
      py::arg("s_um"), py::arg("z_um"), py::arg("rank_rel_tol") = ca::kRankRelTol,
      "Least-squares A of S = A Z from n x 3 arrays of poses (FitError when ill-posed)");
  m.def(
      "fit_cubic_polynomial",
      [](const In& measured, const In& command, double tol) {
        return ca::fit_cubic_polynomial(from_numpy_1d(measured, "measured_um"),
                                        from_numpy_1d(command, "command_um"), tol);
      },
      py::arg("measured_um"), py::arg("command_um"), py::arg("rank_rel_tol") = ca::kRankRelTol,
      "Least-squares cubic c = p(m) (FitError when ill-posed)");

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

  // ---- reproduction -----------------------------------------------------------------------
  namespace rp = ps::reproduction;
  using RoO = rp::ReproduceOptions;
  py::class_<RoO>(m, "ReproduceOptions")
      .def(py::init<>())
      .PS_RW(RoO, seed)
      .PS_RW(RoO, quick)
      .PS_RW(RoO, pid);
  using Sch = rp::Schedule;
  py::class_<Sch>(m, "Schedule")
      .def(py::init<>())
      .PS_RW(Sch, calibration)
      .PS_RW(Sch, travel)
      .PS_RW(Sch, step)
      .PS_RW(Sch, linearity)
      .PS_RW(Sch, repeat_5um)
      .PS_RW(Sch, repeat_10um)
      .def_static("paper", &Sch::paper)
      .def_static("quick", &Sch::quick);
  using RR = rp::ReproductionResult;
  py::class_<RR>(m, "ReproductionResult")
      .PS_RO(RR, options)
      .PS_RO(RR, schedule)
      .PS_RO(RR, calibration)
      .PS_RO(RR, travel)
      .PS_RO(RR, step)
      .PS_RO(RR, linearity)
      .PS_RO(RR, repeat_5um)
      .PS_RO(RR, repeat_10um)
      .PS_RO(RR, simulated_time_s)
      .PS_RO(RR, wall_time_s)
      .def(
          "summary", [](const RR& r) { return json_to_python(rp::summary_json(r)); },
          "summary_json() as a Python dict");
  m.def(
      "reproduce",
      [](const ps::config::ProjectConfig& c, const RoO& o) {
        py::gil_scoped_release nogil;
        return rp::reproduce(c, o);
      },
      py::arg("config"), py::arg_v("options", RoO{}, "ReproduceOptions()"),
      "Calibration and the paper's four experiments on the twin (docs/experiments.md)");
  m.def(
      "summary_json", [](const RR& r) { return json_to_python(rp::summary_json(r)); },
      py::arg("result"), "The machine-readable summary as a dict (json.loads of its dump())");
  // ---- hinge search (docs/design.md), calibration files, the report -------------------------
  py::class_<d::SearchRange>(m, "SearchRange", "Grid values min, min + step, ... up to max [m]")
      .def(py::init<>())
      .def(py::init([](double min_m, double max_m, double step_m) {
             return d::SearchRange{min_m, max_m, step_m};
           }),
           py::arg("min_m"), py::arg("max_m"), py::arg("step_m"))
      .PS_RW(d::SearchRange, min_m)
      .PS_RW(d::SearchRange, max_m)
      .PS_RW(d::SearchRange, step_m);
  py::class_<d::HingeSearchSpace>(m, "HingeSearchSpace",
                                  "The grid over t, R, b and L; the default holds Table 3")
      .def(py::init<>())
      .PS_RW(d::HingeSearchSpace, thickness)
      .PS_RW(d::HingeSearchSpace, radius)
      .PS_RW(d::HingeSearchSpace, width)
      .PS_RW(d::HingeSearchSpace, link_length);
  py::class_<d::SearchConstraints>(m, "SearchConstraints")
      .def(py::init<>())
      .PS_RW(d::SearchConstraints, max_stiffness_ratio)
      .PS_RW(d::SearchConstraints, min_stress_margin)
      .PS_RW(d::SearchConstraints, max_thickness_to_radius)
      .PS_RW(d::SearchConstraints, min_natural_frequency_Hz);
  py::enum_<d::SearchRanking>(m, "SearchRanking")
      .value("NATURAL_FREQUENCY", d::SearchRanking::natural_frequency)
      .value("STRESS_MARGIN", d::SearchRanking::stress_margin);
  py::class_<d::HingeCandidate>(m, "HingeCandidate")
      .PS_RO(d::HingeCandidate, hinge)
      .PS_RO(d::HingeCandidate, evaluation);
  py::class_<d::HingeSearchResult>(m, "HingeSearchResult")
      .PS_RO(d::HingeSearchResult, evaluated_count)
      .PS_RO(d::HingeSearchResult, geometry_rejected_count)
      .PS_RO(d::HingeSearchResult, feasible_count)
      .PS_RO(d::HingeSearchResult, candidates);
  m.def(
      "search_hinge_designs",
      [](const d::DesignInputs& base, const d::HingeSearchSpace& space,
         const d::SearchConstraints& constraints, std::size_t max_candidates,
         d::SearchRanking ranking) {
        py::gil_scoped_release nogil;
        return d::search_hinge_designs(base, space, constraints, max_candidates, ranking);
      },
      py::arg("base"), py::arg_v("space", d::HingeSearchSpace{}, "HingeSearchSpace()"),
      py::arg_v("constraints", d::SearchConstraints{}, "SearchConstraints()"),
      py::arg("max_candidates") = 10,
      py::arg_v("ranking", d::SearchRanking::natural_frequency, "SearchRanking.NATURAL_FREQUENCY"),
      "Grid search over the hinge dimensions (`piezoshift design --search`), best first");

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
  m.def(
      "write_report",
      [](const RR& result, const std::string& directory, const std::string& config_label) {
        const rp::ReportFiles f = rp::write_report(result, directory, config_label);
        py::dict out;
        out["markdown"] = f.markdown.string();
        out["html"] = f.html.string();
        py::list figures;
        for (const auto& p : f.figures)
          figures.append(p.string());
        py::list data;
        for (const auto& p : f.data)
          data.append(p.string());
        out["figures"] = figures;
        out["data"] = data;
        return out;
      },
      py::arg("result"), py::arg("directory"), py::arg("config_label") = "built-in (paper)",
      "Writes report.md, report.html, the figures (gnuplot) and the data of a reproduce() result; "
      "returns their paths");
}
