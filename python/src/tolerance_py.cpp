// Bindings of the tolerance module: a study loaded from its files, and one sample (or one
// sensitivity run) from the study's description, which is what a Dask worker is handed
// (python/piezoshift/tolerance.py drives both; docs/tolerance.md). Samples cross as the JSON
// text of their records, which reads back bit for bit, so a study run on workers writes the same
// bytes as one run on local threads.
#include <pybind11/functional.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "bindings.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/tolerance/study_run.hpp"
#include "values.hpp"

namespace piezoshift::python {

namespace {

namespace tol = ps::tolerance;

tol::Study load(const std::string& tolerances, const std::string& config, const std::string& spec,
                std::uint64_t samples, std::uint64_t seed, const std::string& procedure,
                const std::string& experiments) {
  const auto p = tol::procedure_named(procedure);
  if (!p)
    throw ps::core::InputError(fmt::format("procedure: {} is not paper or improved", procedure));
  const auto e = tol::experiment_set_named(experiments);
  if (!e)
    throw ps::core::InputError(fmt::format("experiments: {} is not quick or table4", experiments));
  if (samples < 1)
    throw ps::core::InputError("samples: at least 1");
  tol::StudyInputs in;
  in.tolerances = tolerances;
  in.config = config;
  in.spec = spec;
  in.samples = samples;
  in.options.seed = seed;
  in.options.procedure = *p;
  in.options.experiments = *e;
  return tol::load_study(in);
}

nlohmann::json parse(const std::string& text, const char* what) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw ps::core::InputError(fmt::format("{}: not JSON: {}", what, e.what()));
  }
}

std::vector<tol::SampleResult> samples_of(const tol::Study& s,
                                          const std::vector<std::string>& texts) {
  std::vector<tol::SampleResult> out;
  for (const std::string& t : texts)
    out.push_back(tol::sample_from_json(s.set, parse(t, "a sample"), "a sample"));
  return out;
}

std::string run_sample(const std::string& description, std::uint64_t index) {
  const tol::Study s = tol::study_from_description(parse(description, "the study's description"));
  if (index >= s.samples)
    throw ps::core::InputError(fmt::format("sample {}: the study has {}", index, s.samples));
  return tol::sample_json(s.set, tol::run_study_sample(s, index)).dump();
}

std::string run_sensitivity_case(const std::string& description, std::size_t k) {
  const tol::Study s = tol::study_from_description(parse(description, "the study's description"));
  const std::vector<std::vector<double>> devs = tol::sensitivity_deviations(s.set);
  if (k >= devs.size())
    throw ps::core::InputError(fmt::format("sensitivity run {}: there are {}", k, devs.size()));
  return tol::sample_json(s.set, tol::run_sample(s.config, s.set, devs[k], k, s.options)).dump();
}

py::dict write_outputs(const tol::Study& s, const std::string& out,
                       const std::vector<std::string>& samples, bool figures,
                       const std::optional<std::vector<std::string>>& sensitivity_runs) {
  std::optional<nlohmann::json> sensitivity;
  if (sensitivity_runs)
    sensitivity = tol::sensitivity_from_runs(s, samples_of(s, *sensitivity_runs));
  const tol::StudyOutputs o =
      tol::write_study_outputs(s, samples_of(s, samples), out, figures, sensitivity);
  py::dict d;
  d["samples"] = o.samples;
  d["valid"] = o.valid;
  d["pass"] = o.pass;
  d["fraction"] = o.fraction;
  d["markdown"] = o.markdown.string();
  d["html"] = o.html.string();
  return d;
}

}  // namespace

void bind_tolerance(py::module_& m) {
  py::class_<tol::Study>(m, "ToleranceStudy",
                         "A tolerance study loaded from its files (docs/tolerance.md); run it with "
                         "piezoshift.tolerance.run_study")
      .def_property_readonly("samples", [](const tol::Study& s) { return s.samples; })
      .def_property_readonly("description",
                             [](const tol::Study& s) { return tol::description(s).dump(); })
      .def_property_readonly("header", [](const tol::Study& s) { return s.header.dump(); })
      .def_property_readonly(
          "sensitivity_runs",
          [](const tol::Study& s) { return tol::sensitivity_deviations(s.set).size(); })
      .def(
          "resumed",
          [](const tol::Study& s, const std::string& out,
             std::uint64_t index) -> std::optional<std::string> {
            if (auto r = tol::resumed_sample(s, out, index))
              return tol::sample_json(s.set, *r).dump();
            return std::nullopt;
          },
          py::arg("out"), py::arg("index"))
      .def(
          "record",
          [](const tol::Study& s, const std::string& out, const std::string& sample) {
            tol::record_sample(s, out, samples_of(s, {sample}).at(0));
          },
          py::arg("out"), py::arg("sample"))
      .def(
          "run_local",
          [](const tol::Study& s, const std::string& out, const std::vector<std::uint64_t>& indices,
             unsigned jobs) {
            std::vector<std::string> texts;
            for (const tol::SampleResult& r :
                 tol::run_study_samples(s, indices, out, jobs, tol::progress_lines("tolerance")))
              texts.push_back(tol::sample_json(s.set, r).dump());
            return texts;
          },
          py::arg("out"), py::arg("indices"), py::arg("jobs") = 0,
          py::call_guard<py::gil_scoped_release>())
      .def(
          "run_sensitivity_local",
          [](const tol::Study& s, unsigned jobs) {
            std::vector<std::string> texts;
            for (const tol::SampleResult& r :
                 tol::run_sensitivity(s, jobs, tol::progress_lines("tolerance sensitivity")))
              texts.push_back(tol::sample_json(s.set, r).dump());
            return texts;
          },
          py::arg("jobs") = 0, py::call_guard<py::gil_scoped_release>())
      .def("write_outputs", &write_outputs, py::arg("out"), py::arg("samples"),
           py::arg("figures") = false, py::arg("sensitivity_runs") = std::nullopt);
  m.def("load_tolerance_study", &load, py::arg("tolerances"), py::arg("config") = "",
        py::arg("spec") = "", py::arg("samples") = 100, py::arg("seed") = 1,
        py::arg("procedure") = "paper", py::arg("experiments") = "quick",
        "Reads and checks a tolerance study's files (InputError naming the file and key)");
  m.def(
      "tolerance_progress_lines",
      [](std::string what) { return tol::progress_lines(std::move(what)); }, py::arg("what"),
      "progress(done, total, elapsed_s): the progress lines `piezoshift tolerance` prints on "
      "stderr, at most one a second");
  m.def("tolerance_run_sample", &run_sample, py::arg("description"), py::arg("index"),
        py::call_guard<py::gil_scoped_release>(),
        "Sample `index` of the study described (ToleranceStudy.description), as its record's "
        "JSON text: what a Dask worker runs");
  m.def("tolerance_run_sensitivity", &run_sensitivity_case, py::arg("description"), py::arg("k"),
        py::call_guard<py::gil_scoped_release>(),
        "Run k of the sensitivity table (0: nominal, then each tolerance at its minimum and "
        "maximum), as JSON text");
}

}  // namespace piezoshift::python
