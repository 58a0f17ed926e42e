// Bindings of the reproduction module: reproduce() (calibration and the paper's four
// experiments), its machine-readable summary as a dict and the written report.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <nlohmann/json.hpp>
#include <string>

#include "bindings.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/reproduction/report.hpp"
#include "piezoshift/reproduction/reproduction.hpp"
#include "piezoshift/reproduction/summary.hpp"
#include "values.hpp"

namespace piezoshift::python {

namespace {

namespace rp = ps::reproduction;

void bind_results(py::module_& m) {
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
}

void bind_runs(py::module_& m) {
  using RoO = rp::ReproduceOptions;
  using RR = rp::ReproductionResult;
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

}  // namespace

void bind_reproduction(py::module_& m) {
  bind_results(m);
  bind_runs(m);
}

}  // namespace piezoshift::python
