// `piezoshift tolerance`: which tolerances matter, and what fraction of stages built with them
// meet the spec after calibration (issue 33, docs/tolerance.md).
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/atomic_file.hpp"
#include "piezoshift/io/input_file.hpp"
#include "piezoshift/io/plot.hpp"
#include "piezoshift/runtime/safety_ranges.hpp"
#include "piezoshift/tolerance/tolerance_summary.hpp"
#include "sample_pool.hpp"
#include "whole_number.hpp"

namespace piezoshift::app {
namespace {

namespace fs = std::filesystem;
using tolerance::SampleResult;

struct Options {
  std::string config;
  std::string tolerances;
  std::string spec;
  std::string out = "tolerance-study";
  std::string procedure = "paper";
  std::string shard;  // "i/N"
  std::uint64_t samples = 100;
  std::uint64_t seed = 1;
  unsigned jobs = 0;
  std::int64_t sample = -1;  // rerun one sample alone
  bool sensitivity = false;
  bool figures = false;
  std::vector<std::string> shard_files;  // merge
};

// "i/N" with 0 <= i < N.
std::optional<std::pair<std::uint64_t, std::uint64_t>> parse_shard(const std::string& text) {
  const std::size_t slash = text.find('/');
  if (slash == std::string::npos)
    return std::nullopt;
  std::uint64_t i = 0, n = 0;
  const auto num = [](std::string_view s, std::uint64_t& v) {
    const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
    return !s.empty() && r.ec == std::errc() && r.ptr == s.data() + s.size();
  };
  if (!num(std::string_view(text).substr(0, slash), i) ||
      !num(std::string_view(text).substr(slash + 1), n) || n == 0 || i >= n)
    return std::nullopt;
  return std::pair{i, n};
}

nlohmann::json read_json(const std::string& path) {
  const std::string text = io::read_input_file(path, io::kMaxDataFileBytes);
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw core::InputError(fmt::format("{}: not JSON: {}", path, e.what()));
  }
}

fs::path record_path(const std::string& out, std::uint64_t index) {
  return fs::path(out) / "samples" / fmt::format("sample-{:06}.json", index);
}

// A record written by an earlier run of the same study, or nothing (absent, or another study's:
// then it is run again and overwritten).
std::optional<SampleResult> resumed(const fs::path& path, const nlohmann::json& header,
                                    const tolerance::ToleranceSet& set) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec))
    return std::nullopt;
  const nlohmann::json j = read_json(path.string());
  if (!j.contains("study") || j.at("study") != header || !j.contains("sample"))
    return std::nullopt;
  return tolerance::sample_from_json(set, j.at("sample"), path.string());
}

struct Study {
  config::ProjectConfig config;
  tolerance::ToleranceSet set;
  tolerance::Spec spec;
  tolerance::StudyOptions options;
  nlohmann::json header;
};

Study load_study(const Options& o) {
  Study s;
  if (!o.config.empty())
    s.config = runtime::load_installation_config(o.config).project;
  if (o.tolerances.empty())
    throw core::InputError("tolerance: --tolerances FILE is required");
  s.set = tolerance::load_tolerances(o.tolerances, s.config);
  s.spec = o.spec.empty() ? tolerance::parse_spec("", "no spec") : tolerance::load_spec(o.spec);
  s.options.seed = o.seed;
  s.options.procedure =
      o.procedure == "improved" ? tolerance::Procedure::kImproved : tolerance::Procedure::kPaper;
  s.header = tolerance::study_header(s.set, s.options, o.samples);
  s.header["tolerance_file"] = o.tolerances;
  s.header["config"] = o.config.empty() ? "built-in defaults" : o.config;
  return s;
}

// The samples of `indices`, each resumed from its record or run and recorded.
std::vector<SampleResult> run_samples(const Study& s, const std::vector<std::uint64_t>& indices,
                                      const Options& o) {
  std::vector<SampleResult> results(indices.size());
  std::vector<std::size_t> todo;
  for (std::size_t k = 0; k < indices.size(); ++k) {
    if (auto r = resumed(record_path(o.out, indices[k]), s.header, s.set))
      results[k] = std::move(*r);
    else
      todo.push_back(k);
  }
  if (todo.size() < indices.size())
    fmt::print(stderr, "piezoshift: tolerance: {} sample(s) resumed from {}\n",
               indices.size() - todo.size(), (fs::path(o.out) / "samples").string());
  fs::create_directories(fs::path(o.out) / "samples");
  run_pool(
      todo.size(), o.jobs,
      [&](std::size_t t) {
        const std::size_t k = todo[t];
        const std::vector<double> dev =
            tolerance::draw_deviations(s.set, s.options.seed, indices[k]);
        results[k] = tolerance::run_sample(s.config, s.set, dev, indices[k], s.options);
        const nlohmann::json rec{{"study", s.header},
                                 {"sample", tolerance::sample_json(s.set, results[k])}};
        io::write_file_atomically(record_path(o.out, indices[k]).string(), rec.dump(1) + "\n");
      },
      "tolerance");
  return results;
}

// A metric's distribution over the valid samples: its histogram and its cumulative curve, as the
// change from the median in % (absolute values of a narrow spread, 0.03601 to 0.03605 s, make
// tick labels that overlap); the caption gives the median and the range.
io::Figure metric_figure(std::size_t m, std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const tolerance::Metric& metric = tolerance::metrics()[m];
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
std::vector<std::string> write_figures(const std::vector<SampleResult>& samples,
                                       const std::string& out) {
  std::vector<std::string> stems;
  for (std::size_t m = 0; m < tolerance::metrics().size(); ++m) {
    std::vector<double> v;
    for (const SampleResult& s : samples)
      if (std::isfinite(s.metrics[m]))
        v.push_back(s.metrics[m]);
    if (v.size() < 2 ||
        !(*std::max_element(v.begin(), v.end()) > *std::min_element(v.begin(), v.end())))
      continue;
    const std::string stem = fmt::format("dist_{}", tolerance::metrics()[m].key);
    try {
      io::render(metric_figure(m, std::move(v)), fs::path(out) / stem);
      stems.push_back(stem);
    } catch (const io::PlotError& e) {
      fmt::print(stderr, "piezoshift: tolerance: no figures: {}\n", e.what());
      break;
    }
  }
  return stems;
}

void write_outputs(const Study& s, const std::vector<SampleResult>& samples, const Options& o,
                   const std::optional<nlohmann::json>& sensitivity) {
  const nlohmann::json study = tolerance::study_json(s.set, s.header, s.spec, samples);
  const fs::path out(o.out);
  fs::create_directories(out);
  io::write_file_atomically((out / "tolerance.json").string(), study.dump(1) + "\n");
  io::write_file_atomically((out / "tolerance.csv").string(),
                            tolerance::study_csv(s.set, s.spec, samples));
  if (sensitivity)
    io::write_file_atomically((out / "sensitivity.json").string(), sensitivity->dump(1) + "\n");
  const std::vector<std::string> figures =
      o.figures ? write_figures(samples, o.out) : std::vector<std::string>{};
  io::write_file_atomically((out / "tolerance.md").string(),
                            tolerance::study_markdown(s.set, study, sensitivity, figures));
  const nlohmann::json& y = study.at("yield");
  fmt::print("piezoshift tolerance: {} samples, {} valid, {} meet the spec ({:.1f} %)\n",
             y.at("samples").get<std::size_t>(), y.at("valid").get<std::size_t>(),
             y.at("pass").get<std::size_t>(), 100.0 * y.at("fraction").get<double>());
  fmt::print("report: {}\n", (out / "tolerance.md").string());
}

nlohmann::json run_sensitivity(const Study& s, const Options& o) {
  const std::vector<std::vector<double>> devs = tolerance::sensitivity_deviations(s.set);
  std::vector<SampleResult> runs(devs.size());
  run_pool(
      devs.size(), o.jobs,
      [&](std::size_t k) {
        runs[k] = tolerance::run_sample(s.config, s.set, devs[k], k, s.options);
      },
      "tolerance sensitivity");
  return tolerance::sensitivity_json(s.set, runs[0], tolerance::sensitivity_table(s.set, runs));
}

int run(const Options& o) {
  const Study s = load_study(o);
  // A shard writes its samples only: what needs all of them is merge's (or a whole run's).
  if (!o.shard.empty() && (o.sensitivity || o.figures || !o.spec.empty()))
    throw core::InputError(
        "tolerance: --shard writes samples only: give --spec and --figures to `tolerance merge`, "
        "and run --sensitivity without --shard");
  work_begins();        // the samples' calibrations and experiments, the files
  if (o.sample >= 0) {  // one sample alone, e.g. a worst one
    const auto index = static_cast<std::uint64_t>(o.sample);
    const SampleResult r = tolerance::run_sample(
        s.config, s.set, tolerance::draw_deviations(s.set, o.seed, index), index, s.options);
    nlohmann::json j = tolerance::sample_json(s.set, r);
    j["spec_failure"] = tolerance::spec_failure(s.spec, r);
    fmt::print("{}\n", j.dump(2));
    return 0;
  }
  std::uint64_t first = 0, stride = 1;
  if (!o.shard.empty())
    std::tie(first, stride) = *parse_shard(o.shard);  // checked by the option's validator
  std::vector<std::uint64_t> indices;
  for (std::uint64_t i = first; i < o.samples; i += stride)
    indices.push_back(i);
  const std::vector<SampleResult> samples = run_samples(s, indices, o);
  if (!o.shard.empty()) {
    nlohmann::json shard{{"study", s.header}, {"shard", {first, stride}}};
    shard["samples"] = nlohmann::json::array();
    for (const SampleResult& r : samples)
      shard["samples"].push_back(tolerance::sample_json(s.set, r));
    const fs::path path = fs::path(o.out) / fmt::format("shard-{}-of-{}.json", first, stride);
    io::write_file_atomically(path.string(), shard.dump(1) + "\n");
    fmt::print("piezoshift tolerance: shard {}/{}: {} samples in {}\n", first, stride,
               samples.size(), path.string());
    return 0;
  }
  std::optional<nlohmann::json> sensitivity;
  if (o.sensitivity)
    sensitivity = run_sensitivity(s, o);
  write_outputs(s, samples, o, sensitivity);
  return 0;
}

// The shards of one study: the same header in each, every sample exactly once. The study (its
// tolerance file, configuration, seed, procedure and sample count) is the first shard's.
int run_merge(const Options& given) {
  Options o = given;
  {
    const nlohmann::json first = read_json(o.shard_files.at(0));
    try {
      const nlohmann::json& h = first.at("study");
      o.tolerances = h.at("tolerance_file").get<std::string>();
      o.config = h.at("config").get<std::string>();
      if (o.config == "built-in defaults")
        o.config.clear();
      o.seed = h.at("seed").get<std::uint64_t>();
      o.samples = h.at("samples").get<std::uint64_t>();
      o.procedure = h.at("procedure").get<std::string>();
    } catch (const nlohmann::json::exception& e) {
      throw core::InputError(fmt::format("{}: not a shard file: {}", o.shard_files[0], e.what()));
    }
  }
  const Study s = load_study(o);
  std::vector<std::optional<SampleResult>> by_index(o.samples);
  for (const std::string& path : o.shard_files) {
    const nlohmann::json j = read_json(path);
    if (!j.contains("study") || j.at("study") != s.header)
      throw core::InputError(fmt::format(
          "{}: a shard of another study (tolerances, config, seed, procedure or --samples differ)",
          path));
    for (const nlohmann::json& rec : j.at("samples")) {
      SampleResult r = tolerance::sample_from_json(s.set, rec, path);
      if (r.index >= o.samples || by_index[r.index])
        throw core::InputError(fmt::format("{}: sample {} twice or out of range", path, r.index));
      by_index[r.index] = std::move(r);
    }
  }
  std::vector<SampleResult> samples;
  for (std::uint64_t i = 0; i < o.samples; ++i) {
    if (!by_index[i])
      throw core::InputError(fmt::format("merge: sample {} is in no shard given", i));
    samples.push_back(std::move(*by_index[i]));
  }
  work_begins();  // the outputs
  write_outputs(s, samples, o, std::nullopt);
  return 0;
}

void add_study_options(CLI::App* cmd, Options& o) {
  cmd->add_option("--tolerances", o.tolerances, "TOML tolerance file (docs/tolerance.md)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--config", o.config, "TOML configuration: the nominal stage");
  cmd->add_option("--samples", o.samples, "Monte Carlo samples")->check(whole_number(1, 1000000));
  cmd->add_option("--seed", o.seed, "study seed: the draws and the twin's noise")
      ->check(whole_number(0, kAnyUnsigned));
  cmd->add_option("--procedure", o.procedure, "calibration procedure")
      ->check(CLI::IsMember({"paper", "improved"}));
  cmd->add_option("--spec", o.spec, "TOML file with [spec] <metric>_min / <metric>_max");
  cmd->add_option("--out", o.out, "output folder");
  cmd->add_flag("--figures", o.figures, "histograms of the metrics (gnuplot)");
}

}  // namespace

void add_tolerance_command(CLI::App& app, Action& action) {
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "tolerance", "Monte Carlo tolerance study: sensitivity and yield after calibration");
  add_study_options(cmd, *o);
  cmd->add_option("--jobs", o->jobs, "local threads (0: every core)")->check(whole_number(0, 1024));
  cmd->add_option("--shard", o->shard, "run samples i, i+N, ... and write a shard file")
      ->check(CLI::Validator(
          [](std::string& t) -> std::string {
            return parse_shard(t) ? "" : fmt::format("{} is not i/N with 0 <= i < N", t);
          },
          "i/N"));
  cmd->add_option("--sample", o->sample, "rerun sample K alone and print it")
      ->check(whole_number(0, 1000000));
  cmd->add_flag("--sensitivity", o->sensitivity,
                "each tolerance alone at its limits (2 runs per tolerance)");
  CLI::App* merge = cmd->add_subcommand("merge", "merge the shard files of one study");
  merge->add_option("shards", o->shard_files, "shard files (each names its study)")
      ->required()
      ->check(CLI::ExistingFile);
  merge->add_option("--spec", o->spec, "TOML file with [spec] <metric>_min / <metric>_max");
  merge->add_option("--out", o->out, "output folder");
  merge->add_flag("--figures", o->figures, "histograms of the metrics (gnuplot)");
  cmd->callback([o, merge, &action] {
    if (merge->parsed())
      action = [o] { return run_merge(*o); };
    else
      action = [o] { return run(*o); };
  });
}

}  // namespace piezoshift::app
