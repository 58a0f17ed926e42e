// Bindings of the experiments module (docs/experiments.md): the simulated bench, the metrics on
// any data and the paper's four experiments, whose series come back as numpy arrays.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/experiments/metrics_linearity.hpp"
#include "piezoshift/experiments/metrics_repeatability.hpp"
#include "piezoshift/experiments/metrics_step_response.hpp"
#include "piezoshift/experiments/paper_experiments.hpp"
#include "piezoshift/rig/bench.hpp"
#include "piezoshift/runtime/controller_ranges.hpp"
#include "values.hpp"

namespace piezoshift::python {

namespace {

namespace ex = ps::experiments;
namespace rig = ps::rig;
using Scl = ps::control::SemiClosedLoopParams;

// A controller from Python passes the check a calibration file and SPA pass
// (runtime/controller_ranges.hpp) at the loop's rate before a loop runs it.
const Scl& checked(const Scl& p, double loop_sample_time_s) {
  if (const std::string why = ps::runtime::controller_problem(p, loop_sample_time_s); !why.empty())
    throw ps::core::InputError("controller: " + why);
  return p;
}

void bind_bench(py::module_& m) {
  py::enum_<rig::DriveMode>(m, "DriveMode")
      .value("OPEN_LOOP", rig::DriveMode::kOpenLoop)
      .value("ACTUATORS", rig::DriveMode::kActuators)
      .value("POINTS", rig::DriveMode::kPoints);
  using Sm = rig::StaticMeasurement;
  py::class_<Sm>(m, "StaticMeasurement")
      .PS_V3(Sm, points_um)
      .PS_V3(Sm, sgs_um)
      .PS_RO(Sm, window_end_s);

  py::class_<rig::Bench>(m, "Bench")
      .def(py::init([](const ps::config::ProjectConfig& c, const Scl& p, std::uint64_t seed) {
             return std::make_unique<rig::Bench>(c, checked(p, c.twin.daq.sample_time_s), seed);
           }),
           py::arg("config"), py::arg("controller"), py::arg("seed"))
      .def(
          "set_controller",
          [](rig::Bench& b, const Scl& p) { b.set_controller(checked(p, b.sample_time_s())); },
          py::arg("params"))
      .def("controller_params", &rig::Bench::controller_params)
      .def("drive_open_loop", &rig::Bench::drive_open_loop, py::arg("ao_V"))
      .def("drive_actuators", &rig::Bench::drive_actuators, py::arg("target_um"))
      .def("drive_points", &rig::Bench::drive_points, py::arg("zd_um"))
      .def(
          "run", [](rig::Bench& b, double duration_s) { b.run(duration_s); }, py::arg("duration_s"))
      .def(
          "record",
          [](rig::Bench& b, double duration_s) {
            // run() with every tick's time, true mean of P1..P3 and SGS feedback kept.
            std::vector<double> t, z, fb;
            b.run(duration_s, [&](const rig::Bench& bb) {
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
      .def("measure_static", &rig::Bench::measure_static)
      .def_property_readonly("twin", &rig::Bench::twin, py::return_value_policy::reference_internal)
      .def("last_output", &rig::Bench::last_output)
      .def_property_readonly("mode", &rig::Bench::mode)
      .def_property_readonly("time_s", &rig::Bench::time_s)
      .def_property_readonly("sample_time_s", &rig::Bench::sample_time_s)
      .def_property_readonly("ticks", &rig::Bench::ticks);
}

void bind_metric_results(py::module_& m) {
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
}

// Metrics on the caller's own data (lists or arrays); invalid data raises MetricsError.
void bind_metric_functions(py::module_& m) {
  using SrO = ex::StepResponseOptions;
  m.def(
      "step_response_metrics",
      [](const InArray& t, const InArray& y, const SrO& o) {
        const auto tv = from_numpy_1d(t, "t_s");
        const auto yv = from_numpy_1d(y, "y_um");
        return ex::step_response_metrics(tv, yv, o);
      },
      py::arg("t_s"), py::arg("y_um"), py::arg_v("options", SrO{}, "StepResponseOptions()"));
  m.def(
      "running_median",
      [](const InArray& y, std::size_t window) {
        return to_numpy(ex::running_median(from_numpy_1d(y, "y"), window));
      },
      py::arg("y"), py::arg("window"));
  m.def(
      "linearity_metrics",
      [](const InArray& desired, const InArray& measured) {
        return ex::linearity_metrics(from_numpy_1d(desired, "desired_um"),
                                     from_numpy_1d(measured, "measured_um"));
      },
      py::arg("desired_um"), py::arg("measured_um"));
  m.def(
      "repeatability_metrics",
      [](const InArray& measured) {
        return ex::repeatability_metrics(from_numpy_1d(measured, "measured_um"));
      },
      py::arg("measured_um"));
}

void bind_experiment_values(py::module_& m) {
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
}

// The experiments run with the GIL released: they touch no Python object.
void bind_experiment_runs(py::module_& m) {
  using TrO = ex::TravelRangeOptions;
  using StO = ex::StepExperimentOptions;
  using LiO = ex::LinearityOptions;
  using RpO = ex::RepeatabilityOptions;
  m.def(
      "run_travel_range",
      [](const ps::config::ProjectConfig& c, const Scl& p, std::uint64_t seed, const TrO& o) {
        checked(p, c.twin.daq.sample_time_s);
        py::gil_scoped_release nogil;
        return ex::run_travel_range(c, p, seed, o);
      },
      py::arg("config"), py::arg("controller"), py::arg("seed"),
      py::arg_v("options", TrO{}, "TravelRangeOptions()"));
  m.def(
      "run_step_response",
      [](const ps::config::ProjectConfig& c, const Scl& p, std::uint64_t seed, const StO& o) {
        checked(p, c.twin.daq.sample_time_s);
        py::gil_scoped_release nogil;
        return ex::run_step_response(c, p, seed, o);
      },
      py::arg("config"), py::arg("controller"), py::arg("seed"),
      py::arg_v("options", StO{}, "StepExperimentOptions()"));
  m.def(
      "run_linearity",
      [](const ps::config::ProjectConfig& c, const Scl& p, std::uint64_t seed, const LiO& o) {
        checked(p, c.twin.daq.sample_time_s);
        py::gil_scoped_release nogil;
        return ex::run_linearity(c, p, seed, o);
      },
      py::arg("config"), py::arg("controller"), py::arg("seed"),
      py::arg_v("options", LiO{}, "LinearityOptions()"));
  m.def(
      "run_repeatability",
      [](const ps::config::ProjectConfig& c, const Scl& p, std::uint64_t seed, const RpO& o) {
        checked(p, c.twin.daq.sample_time_s);
        py::gil_scoped_release nogil;
        return ex::run_repeatability(c, p, seed, o);
      },
      py::arg("config"), py::arg("controller"), py::arg("seed"),
      py::arg_v("options", RpO{}, "RepeatabilityOptions()"));
}

}  // namespace

void bind_experiments(py::module_& m) {
  bind_bench(m);
  bind_metric_results(m);
  bind_metric_functions(m);
  bind_experiment_values(m);
  bind_experiment_runs(m);
}

}  // namespace piezoshift::python
