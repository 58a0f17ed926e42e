#include "piezoshift/tolerance/study_run.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/atomic_file.hpp"
#include "piezoshift/io/input_file.hpp"
#include "piezoshift/io/plot.hpp"
#include "piezoshift/runtime/safety_ranges.hpp"

namespace piezoshift::tolerance {
namespace {

namespace fs = std::filesystem;

constexpr const char* kBuiltIn = "built-in defaults";

// The study from the files' text: what load_study and a worker share.
Study build_study(const std::string& tolerance_name, std::string tolerance_text,
                  const std::string& config_name, std::string config_text, std::uint64_t samples,
                  const StudyOptions& options) {
  if (const std::string p = samples_problem("tolerance: --samples", samples); !p.empty())
    throw core::InputError(p);
  Study s;
  if (!config_name.empty())
    s.config = runtime::parse_installation_config(config_text, config_name).project;
  const std::string pinned = pin_identified_contact(s.config);
  s.set = parse_tolerances(tolerance_text, tolerance_name, s.config);
  s.spec = parse_spec("", "no spec");
  s.options = options;
  s.samples = samples;
  s.header = study_header(s.set, options, samples);
  s.header["tolerance_file"] = tolerance_name;
  s.header["config"] = config_name.empty() ? kBuiltIn : config_name;
  s.header["pinned"] = pinned;
  s.tolerance_text = std::move(tolerance_text);
  s.config_text = std::move(config_text);
  return s;
}

// A metric's distribution over the valid samples: its histogram and its cumulative curve, as the
// change from the median in % (absolute values of a narrow spread, 0.03601 to 0.03605 s, make
// tick labels that overlap); the caption gives the median and the range.
io::Figure metric_figure(std::size_t m, std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const Metric& metric = metrics()[m];
  const double median = v[v.size() / 2];
  std::vector<double> change_pct, fraction_pct;
  for (std::size_t i = 0; i < v.size(); ++i) {
    change_pct.push_back(median != 0.0 ? 100.0 * (v[i] - median) / std::abs(median) : v[i]);
    fraction_pct.push_back(100.0 * static_cast<double>(i + 1) / static_cast<double>(v.size()));
  }
  const std::string_view name =
      std::string_view(metric.axis)
          .substr(0, std::string_view(metric.axis).find(" ["));  // "first mode [Hz]": "first mode"
  const std::string axis = fmt::format("{}, change from the median [%]", name);
  io::Figure f;
  f.cols = 2;
  f.png = false;
  f.width_px = 900;
  f.height_px = 380;
  f.caption = fmt::format("{}: {} valid samples, median {:.6g}, {:.6g} to {:.6g} ({})",
                          metric.label, v.size(), median, v.front(), v.back(), metric.axis);
  io::Panel hist;
  hist.title = "histogram";
  hist.x_label = axis;
  hist.y_label = "sample count";
  hist.key = "off";
  const double span = change_pct.back() - change_pct.front();
  hist.series.push_back(io::histogram_series("samples", change_pct, span / 20.0));
  io::Panel cdf;
  cdf.title = "cumulative";
  cdf.x_label = axis;
  cdf.y_label = "valid samples at or below [%]";
  cdf.key = "off";
  cdf.series.push_back(io::line_series("cumulative", change_pct, fraction_pct));
  f.panels = {std::move(hist), std::move(cdf)};
  return f;
}

// One figure per metric with a spread; gnuplot missing or failing costs the figures only.
std::vector<ReportFigure> write_figures(const std::vector<SampleResult>& samples,
                                        const fs::path& out) {
  std::vector<ReportFigure> figures;
  for (std::size_t m = 0; m < metrics().size(); ++m) {
    std::vector<double> v;
    for (const SampleResult& s : samples)
      if (std::isfinite(s.metrics[m]))
        v.push_back(s.metrics[m]);
    if (v.size() < 2 ||
        !(*std::max_element(v.begin(), v.end()) > *std::min_element(v.begin(), v.end())))
      continue;
    const std::string stem = fmt::format("dist_{}", metrics()[m].key);
    io::Figure f = metric_figure(m, std::move(v));
    try {
      io::render(f, out / stem);
      figures.push_back({f.caption, stem + ".svg"});
    } catch (const io::PlotError& e) {
      fmt::print(stderr, "piezoshift: tolerance: no figures: {}\n", e.what());
      break;
    }
  }
  return figures;
}

}  // namespace

std::string samples_problem(const std::string& what, std::uint64_t samples) {
  if (samples >= 1 && samples <= kMaxSamples)
    return "";
  return fmt::format("{}: {} samples; a study has 1 to {} (docs/tolerance.md)", what, samples,
                     kMaxSamples);
}

nlohmann::json read_study_json(const fs::path& path) {
  const std::string text = io::read_input_file(path.string(), io::kMaxDataFileBytes);
  // The callback sees each value's depth as the parser reaches it: a deeper one stops the parse
  // before it holds more than kMaxJsonDepth levels.
  struct TooDeep {};
  const auto bounded = [](int depth, nlohmann::json::parse_event_t, nlohmann::json&) {
    if (depth > kMaxJsonDepth)
      throw TooDeep{};
    return true;
  };
  try {
    return nlohmann::json::parse(text, bounded);
  } catch (const TooDeep&) {
    throw core::InputError(fmt::format("{}: nests deeper than {} levels; not a study's file",
                                       path.string(), kMaxJsonDepth));
  } catch (const nlohmann::json::exception& e) {
    throw core::InputError(fmt::format("{}: not JSON: {}", path.string(), e.what()));
  }
}

Study load_study(const StudyInputs& in) {
  if (in.tolerances.empty())
    throw core::InputError("tolerance: --tolerances FILE is required");
  std::string config_text;
  if (!in.config.empty())
    config_text = io::read_input_file(in.config, io::kMaxConfigFileBytes);
  Study s = build_study(in.tolerances, io::read_input_file(in.tolerances, io::kMaxConfigFileBytes),
                        in.config, std::move(config_text), in.samples, in.options);
  if (!in.spec.empty())
    s.spec = load_spec(in.spec);
  return s;
}

nlohmann::json description(const Study& s) {
  return {{"tolerance_file", s.header.at("tolerance_file")},
          {"tolerance_text", s.tolerance_text},
          {"config", s.header.at("config")},
          {"config_text", s.config_text},
          {"samples", s.samples},
          {"seed", s.options.seed},
          {"procedure", procedure_name(s.options.procedure)},
          {"experiments", experiment_set_name(s.options.experiments)}};
}

Study study_from_description(const nlohmann::json& d) {
  try {
    StudyOptions o;
    o.seed = d.at("seed").get<std::uint64_t>();
    const auto procedure = procedure_named(d.at("procedure").get<std::string>());
    const auto experiments = experiment_set_named(d.at("experiments").get<std::string>());
    if (!procedure || !experiments)
      throw core::InputError(
          "not a tolerance study's description: an unknown procedure or "
          "experiment set");
    o.procedure = *procedure;
    o.experiments = *experiments;
    std::string config = d.at("config").get<std::string>();
    if (config == kBuiltIn)
      config.clear();
    return build_study(
        d.at("tolerance_file").get<std::string>(), d.at("tolerance_text").get<std::string>(),
        config, d.at("config_text").get<std::string>(), d.at("samples").get<std::uint64_t>(), o);
  } catch (const nlohmann::json::exception& e) {
    throw core::InputError(fmt::format("not a tolerance study's description: {}", e.what()));
  }
}

SampleResult run_study_sample(const Study& s, std::uint64_t index) {
  return run_sample(s.config, s.set, draw_deviations(s.set, s.options.seed, index), index,
                    s.options);
}

fs::path record_path(const fs::path& out, std::uint64_t index) {
  return out / "samples" / fmt::format("sample-{:06}.json", index);
}

std::optional<SampleResult> resumed_sample(const Study& s, const fs::path& out,
                                           std::uint64_t index) {
  const fs::path path = record_path(out, index);
  std::error_code ec;
  if (!fs::is_regular_file(path, ec))
    return std::nullopt;
  const nlohmann::json j = read_study_json(path);
  if (!j.contains("study") || j.at("study") != s.header || !j.contains("sample"))
    return std::nullopt;
  return sample_from_json(s.set, j.at("sample"), path.string());
}

void record_sample(const Study& s, const fs::path& out, const SampleResult& sample) {
  fs::create_directories(out / "samples");
  const nlohmann::json rec{{"study", s.header}, {"sample", sample_json(s.set, sample)}};
  io::write_file_atomically(record_path(out, sample.index).string(), rec.dump(1) + "\n");
}

std::vector<SampleResult> run_study_samples(const Study& s,
                                            const std::vector<std::uint64_t>& indices,
                                            const fs::path& out, unsigned jobs,
                                            const PoolProgress& progress) {
  std::vector<SampleResult> results(indices.size());
  std::vector<std::size_t> todo;
  for (std::size_t k = 0; k < indices.size(); ++k) {
    if (auto r = resumed_sample(s, out, indices[k]))
      results[k] = std::move(*r);
    else
      todo.push_back(k);
  }
  if (todo.size() < indices.size())
    fmt::print(stderr, "piezoshift: tolerance: {} sample(s) resumed from {}\n",
               indices.size() - todo.size(), (out / "samples").string());
  run_pool(
      todo.size(), jobs,
      [&](std::size_t t) {
        const std::size_t k = todo[t];
        results[k] = run_study_sample(s, indices[k]);
        record_sample(s, out, results[k]);
      },
      progress);
  return results;
}

std::vector<SampleResult> run_sensitivity(const Study& s, unsigned jobs,
                                          const PoolProgress& progress) {
  const std::vector<std::vector<double>> devs = sensitivity_deviations(s.set);
  std::vector<SampleResult> runs(devs.size());
  run_pool(
      devs.size(), jobs,
      [&](std::size_t k) { runs[k] = run_sample(s.config, s.set, devs[k], k, s.options); },
      progress);
  return runs;
}

nlohmann::json sensitivity_from_runs(const Study& s, const std::vector<SampleResult>& runs) {
  if (runs.size() != sensitivity_deviations(s.set).size())
    throw core::InputError(fmt::format("sensitivity: {} runs for {} tolerances", runs.size(),
                                       s.set.tolerances.size()));
  return sensitivity_json(s.set, runs.at(0), sensitivity_table(s.set, runs));
}

StudyOutputs write_study_outputs(const Study& s, const std::vector<SampleResult>& samples,
                                 const fs::path& out, bool figures,
                                 const std::optional<nlohmann::json>& sensitivity) {
  const nlohmann::json study = study_json(s.set, s.header, s.spec, samples);
  fs::create_directories(out);
  io::write_file_atomically((out / "tolerance.json").string(), study.dump(1) + "\n");
  io::write_file_atomically((out / "tolerance.csv").string(), study_csv(s.set, s.spec, samples));
  if (sensitivity)
    io::write_file_atomically((out / "sensitivity.json").string(), sensitivity->dump(1) + "\n");
  const std::vector<ReportFigure> figs =
      figures ? write_figures(samples, out) : std::vector<ReportFigure>{};
  const std::vector<reproduction::Block> report = study_report(s.set, study, sensitivity, figs);
  StudyOutputs o;
  o.markdown = out / "tolerance.md";
  o.html = out / "tolerance.html";
  io::write_file_atomically(o.markdown.string(), reproduction::to_markdown(report));
  io::write_file_atomically(o.html.string(), reproduction::to_html(report, "Tolerance study"));
  const nlohmann::json& y = study.at("yield");
  o.samples = y.at("samples").get<std::size_t>();
  o.valid = y.at("valid").get<std::size_t>();
  o.pass = y.at("pass").get<std::size_t>();
  o.fraction = y.at("fraction").get<double>();
  return o;
}

}  // namespace piezoshift::tolerance
