// `piezoshift tolerance`: which tolerances matter, and what fraction of stages built with them
// meet the spec after calibration (docs/tolerance.md).
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/io/atomic_file.hpp"
#include "piezoshift/io/input_file.hpp"
#include "piezoshift/tolerance/study_run.hpp"
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
  std::string experiments = "quick";
  std::string scheduler;  // a Dask scheduler: the study runs through the Python package
  std::string shard;      // "i/N"
  std::uint64_t samples = 100;
  std::uint64_t seed = 1;
  unsigned jobs = 0;
  std::int64_t sample = -1;  // rerun one sample alone
  bool sensitivity = false;
  bool figures = false;
  std::vector<std::string> shard_files;  // merge
};

// "i/N" with 0 <= i < N <= kMaxSamples (N is checked against --samples once it is known).
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
      !num(std::string_view(text).substr(slash + 1), n) || n == 0 || i >= n ||
      n > tolerance::kMaxSamples)
    return std::nullopt;
  return std::pair{i, n};
}

// "" or why text is not the address of a Dask scheduler: SCHEME://HOST:PORT for the schemes
// dask.distributed connects by (tcp, tls, ws, wss, ucx), or inproc://NAME; the same check as
// python/piezoshift/tolerance.py's, made before an interpreter starts.
std::string scheduler_problem(const std::string& text) {
  const std::string form =
      "give SCHEME://HOST:PORT (tcp, tls, ws, wss or ucx; e.g. "
      "tcp://127.0.0.1:8786) or inproc://NAME";
  for (const char c : text)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f || c == ' ')
      return fmt::format("'{}' holds a space or a control character; {}", text, form);
  const std::size_t sep = text.find("://");
  if (sep == std::string::npos)
    return fmt::format("'{}' is not a scheduler address; {}", text, form);
  const std::string scheme = text.substr(0, sep), rest = text.substr(sep + 3);
  if (scheme == "inproc")
    return rest.empty() ? fmt::format("'{}' names no process; {}", text, form) : "";
  if (scheme != "tcp" && scheme != "tls" && scheme != "ws" && scheme != "wss" && scheme != "ucx")
    return fmt::format("'{}': unknown scheme '{}'; {}", text, scheme, form);
  const std::size_t colon = rest.rfind(':');
  unsigned port = 0;
  const std::string_view digits =
      colon == std::string::npos ? std::string_view{} : std::string_view(rest).substr(colon + 1);
  const auto r = std::from_chars(digits.data(), digits.data() + digits.size(), port);
  if (colon == 0 || colon == std::string::npos || digits.empty() || r.ec != std::errc() ||
      r.ptr != digits.data() + digits.size() || port < 1 || port > 65535 ||
      rest.find_first_of("/?#@") != std::string::npos)
    return fmt::format("'{}' needs a host and a port 1..65535; {}", text, form);
  return "";
}

tolerance::Study load_study(const Options& o) {
  tolerance::StudyInputs in;
  in.tolerances = o.tolerances;
  in.config = o.config;
  in.spec = o.spec;
  in.samples = o.samples;
  in.options.seed = o.seed;
  // Both checked by their options' IsMember, and read back from a shard's header by merge.
  const auto procedure = tolerance::procedure_named(o.procedure);
  const auto experiments = tolerance::experiment_set_named(o.experiments);
  if (!procedure || !experiments)
    throw core::InputError(fmt::format("tolerance: procedure {} or experiments {} unknown",
                                       o.procedure, o.experiments));
  in.options.procedure = *procedure;
  in.options.experiments = *experiments;
  return tolerance::load_study(in);
}

void write_outputs(const tolerance::Study& s, const std::vector<SampleResult>& samples,
                   const Options& o, const std::optional<nlohmann::json>& sensitivity) {
  const tolerance::StudyOutputs out =
      tolerance::write_study_outputs(s, samples, o.out, o.figures, sensitivity);
  fmt::print("piezoshift tolerance: {} samples, {} valid, {} meet the spec ({:.1f} %)\n",
             out.samples, out.valid, out.pass, 100.0 * out.fraction);
  fmt::print("report: {} and {}\n", out.markdown.string(), out.html.string());
}

// The study on a Dask cluster: the Python package's `python3 -m piezoshift.tolerance`, given the
// same study, in this process's place (its exit status is the command's). The interpreter is
// $PIEZOSHIFT_PYTHON, else python3; without the package it says so and exits 2.
[[noreturn]] void run_on_scheduler(const Options& o) {
  const char* env = std::getenv("PIEZOSHIFT_PYTHON");
  const std::string python = env != nullptr && *env != '\0' ? env : "python3";
  std::vector<std::string> args{
      python,
      "-c",
      "import sys\n"
      "try:\n"
      "    import piezoshift.tolerance as t\n"
      "except ImportError as e:\n"
      "    print(f'piezoshift: error: tolerance --scheduler needs the Python package piezoshift "
      "and dask.distributed ({e}): docs/python.md, docs/tolerance.md', file=sys.stderr)\n"
      "    sys.exit(2)\n"
      "sys.exit(t.main(sys.argv[1:]))\n",
      "--scheduler",
      o.scheduler,
      "--tolerances",
      o.tolerances,
      "--samples",
      std::to_string(o.samples),
      "--seed",
      std::to_string(o.seed),
      "--procedure",
      o.procedure,
      "--experiments",
      o.experiments,
      "--out",
      o.out};
  for (const auto& [flag, value] : {std::pair{"--config", &o.config}, {"--spec", &o.spec}})
    if (!value->empty())
      args.insert(args.end(), {flag, *value});
  if (o.figures)
    args.emplace_back("--figures");
  if (o.sensitivity)
    args.emplace_back("--sensitivity");
  std::vector<char*> argv;
  for (std::string& a : args)
    argv.push_back(a.data());
  argv.push_back(nullptr);
  std::fflush(stdout);
  ::execvp(argv[0], argv.data());
  throw core::InputError(
      fmt::format("tolerance --scheduler: cannot run {}: {}", python, std::strerror(errno)));
}

int run(const Options& o) {
  if (!o.shard.empty()) {
    // Sample i of shard i/N is the shard's first: a shard past the samples would run none.
    const std::uint64_t n = parse_shard(o.shard)->second;  // checked by the option's validator
    if (n > o.samples)
      throw core::InputError(fmt::format(
          "tolerance --shard {}: {} shards for {} samples (--samples {}); N may be at most the "
          "sample count, so that every shard runs a sample",
          o.shard, n, o.samples, o.samples));
  }
  const tolerance::Study s = load_study(o);
  // A shard writes its samples only: what needs all of them is merge's (or a whole run's).
  if (!o.shard.empty() && (o.sensitivity || o.figures || !o.spec.empty()))
    throw core::InputError(
        "tolerance: --shard writes samples only: give --spec and --figures to `tolerance merge`, "
        "and run --sensitivity without --shard");
  if (!o.scheduler.empty() && (!o.shard.empty() || o.sample >= 0))
    throw core::InputError(
        "tolerance: --scheduler runs a whole study: without --shard or --sample (run those "
        "locally)");
  work_begins();  // the samples' calibrations and experiments, the files
  if (!o.scheduler.empty())
    run_on_scheduler(o);
  if (o.sample >= 0) {  // one sample alone, e.g. a worst one
    const auto index = static_cast<std::uint64_t>(o.sample);
    const SampleResult r = tolerance::run_study_sample(s, index);
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
  const std::vector<SampleResult> samples = tolerance::run_study_samples(
      s, indices, o.out, o.jobs, tolerance::progress_lines("tolerance"));
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
    sensitivity = tolerance::sensitivity_from_runs(
        s,
        tolerance::run_sensitivity(s, o.jobs, tolerance::progress_lines("tolerance sensitivity")));
  write_outputs(s, samples, o, sensitivity);
  return 0;
}

// The shards of one study: the same header in each, every sample exactly once. The study (its
// tolerance file, configuration, seed, procedure and sample count) is the first shard's.
int run_merge(const Options& given) {
  Options o = given;
  {
    const nlohmann::json first = tolerance::read_study_json(o.shard_files.at(0));
    try {
      const nlohmann::json& h = first.at("study");
      o.tolerances = h.at("tolerance_file").get<std::string>();
      o.config = h.at("config").get<std::string>();
      if (o.config == "built-in defaults")
        o.config.clear();
      o.seed = h.at("seed").get<std::uint64_t>();
      o.samples = h.at("samples").get<std::uint64_t>();
      if (const std::string p = tolerance::samples_problem(o.shard_files[0], o.samples); !p.empty())
        throw core::InputError(p);
      o.procedure = h.at("procedure").get<std::string>();
      o.experiments = h.at("experiments").get<std::string>();
    } catch (const nlohmann::json::exception& e) {
      throw core::InputError(fmt::format("{}: not a shard file: {}", o.shard_files[0], e.what()));
    }
  }
  const tolerance::Study s = load_study(o);
  std::vector<std::optional<SampleResult>> by_index(o.samples);
  for (const std::string& path : o.shard_files) {
    const nlohmann::json j = tolerance::read_study_json(path);
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
  cmd->add_option("--experiments", o.experiments,
                  "what each sample measures: quick (about 0.45 s of CPU) or table4 (the "
                  "paper's protocols whole)")
      ->check(CLI::IsMember({"quick", "table4"}));
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
  cmd->add_option("--scheduler", o->scheduler,
                  "a Dask scheduler (tcp://host:8786): the samples run on its workers through "
                  "the Python package (docs/tolerance.md)")
      ->check(CLI::Validator([](std::string& t) -> std::string { return scheduler_problem(t); },
                             "ADDRESS"));
  cmd->add_option("--shard", o->shard, "run samples i, i+N, ... and write a shard file")
      ->check(CLI::Validator(
          [](std::string& t) -> std::string {
            return parse_shard(t) ? ""
                                  : fmt::format("{} is not i/N with 0 <= i < N <= {}", t,
                                                tolerance::kMaxSamples);
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
