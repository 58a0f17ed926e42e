#pragma once
// A tolerance study as one runs it (docs/tolerance.md): its inputs loaded (the
// tolerances, the nominal configuration, the spec), its samples run and recorded one file each
// (so an interrupted run resumes from what it has), and its outputs written. `piezoshift
// tolerance` runs the samples on local threads; the Python API (python/piezoshift/tolerance.py)
// runs them on Dask workers from the study's description, which carries the files' text, so a
// worker needs neither the files nor a shared filesystem.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "piezoshift/config/project_config.hpp"
#include "piezoshift/tolerance/sample_pool.hpp"
#include "piezoshift/tolerance/tolerance_summary.hpp"

namespace piezoshift::tolerance {

//! A study's sample count, everywhere it is given (--samples, a shard's or a description's
//! header, the Python API): merge holds one result a sample, so a shard claiming 1e12 samples
//! ended in std::bad_alloc. 10^6 quick samples are about 5 CPU-days.
inline constexpr std::uint64_t kMaxSamples = 1000000;
//! "" or why `samples` is not a study's sample count, naming `what` (the option or the file).
std::string samples_problem(const std::string& what, std::uint64_t samples);
//! The deepest nesting of a study's JSON file (a record or a shard nests 4 levels): a file of
//! 64 MiB of '[' took 5 GB to parse; it is refused at the first level past this one.
inline constexpr int kMaxJsonDepth = 16;

struct StudyInputs {
  std::string tolerances;  //!< path of the tolerance file
  std::string config;      //!< path of the nominal configuration; "" for the built-in defaults
  std::string spec;        //!< path of the spec; "" for none
  std::uint64_t samples = 100;
  StudyOptions options;
};

struct Study {
  config::ProjectConfig config;
  ToleranceSet set;
  Spec spec;
  StudyOptions options;
  std::uint64_t samples = 0;
  //! study_header() and the files' names: what a record or shard must match to be used
  nlohmann::json header;
  std::string tolerance_text, config_text;  //!< for description()
};

//! Reads and checks the files; core::InputError naming the file and key otherwise.
Study load_study(const StudyInputs& inputs);
//! The study as plain JSON: the header's names and options with the files' text. A worker
//! rebuilds the same study from it (spec aside: a worker runs samples, it does not judge them).
nlohmann::json description(const Study& study);
Study study_from_description(const nlohmann::json& description);

//! sample `index` of the study: its deviations drawn from (seed, index), built, calibrated and
//! measured. The same bytes whichever thread, process or machine runs it.
SampleResult run_study_sample(const Study& study, std::uint64_t index);

//! A study's JSON file (a record, a shard), whole; core::InputError naming the file when it
//! cannot be read, is not JSON or nests deeper than kMaxJsonDepth.
nlohmann::json read_study_json(const std::filesystem::path& path);

//! <out>/samples/sample-NNNNNN.json
std::filesystem::path record_path(const std::filesystem::path& out, std::uint64_t index);
//! The record an earlier run of the same study wrote for `index`, or nothing (absent, or another
//! study's: then the sample is run again and its record overwritten).
std::optional<SampleResult> resumed_sample(const Study& study, const std::filesystem::path& out,
                                           std::uint64_t index);
void record_sample(const Study& study, const std::filesystem::path& out,
                   const SampleResult& sample);

//! The samples of `indices` in that order, each resumed from its record or run (on `jobs` local
//! threads) and recorded.
std::vector<SampleResult> run_study_samples(const Study& study,
                                            const std::vector<std::uint64_t>& indices,
                                            const std::filesystem::path& out, unsigned jobs,
                                            const PoolProgress& progress);

//! The runs sensitivity_deviations() asks for, in its order, on `jobs` local threads.
std::vector<SampleResult> run_sensitivity(const Study& study, unsigned jobs,
                                          const PoolProgress& progress);
//! sensitivity_json() from those runs (made here or on Dask workers).
nlohmann::json sensitivity_from_runs(const Study& study, const std::vector<SampleResult>& runs);

struct StudyOutputs {
  std::size_t samples = 0, valid = 0, pass = 0;
  double fraction = 0.0;
  std::filesystem::path markdown, html;
};
//! tolerance.json, tolerance.csv, sensitivity.json (when given), the figures (when asked:
//! gnuplot missing costs the figures only, said on stderr), tolerance.md and tolerance.html.
StudyOutputs write_study_outputs(const Study& study, const std::vector<SampleResult>& samples,
                                 const std::filesystem::path& out, bool figures,
                                 const std::optional<nlohmann::json>& sensitivity);

}  // namespace piezoshift::tolerance
