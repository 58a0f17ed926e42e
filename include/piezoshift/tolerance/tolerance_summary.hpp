#pragma once
// A tolerance study's results (docs/tolerance.md): the spec and the yield against it,
// the worst samples, the sensitivity table, and the files: tolerance.json (the study, every
// sample, the yield and the worst samples; no wall times, so the same study gives the same bytes
// whatever the number of jobs or shards), tolerance.csv, a per-sample record for resuming, and
// tolerance.md and tolerance.html.
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "piezoshift/reproduction/document.hpp"
#include "piezoshift/tolerance/tolerance_study.hpp"

namespace piezoshift::tolerance {

//! Optional bounds on the metrics: [spec] <metric>_min / <metric>_max (tolerance_study.hpp's keys).
struct Spec {
  std::vector<double> min, max;  //!< per metrics(); -inf / +inf where not bounded
  std::string source;
  bool empty() const;
};
//! Throws core::InputError naming the file and key (unknown metric, a min above its max).
Spec parse_spec(std::string_view text, const std::string& source_name);
Spec load_spec(const std::string& path);

//! The smallest margin of the sample to the spec's bounds, as a fraction of each bound (< 0:
//! fails; -inf: not valid or a bounded metric not measured); +inf with no bound.
double spec_margin(const Spec& spec, const SampleResult& sample);
//! "" when the sample meets the spec, else the first reason.
std::string spec_failure(const Spec& spec, const SampleResult& sample);

//! The study's identity: what must match for a record to be resumed or a shard to be merged.
nlohmann::json study_header(const ToleranceSet& set, const StudyOptions& options,
                            std::uint64_t samples);
nlohmann::json sample_json(const ToleranceSet& set, const SampleResult& sample);
//! Throws core::InputError (source names the file) when the record does not fit the set.
SampleResult sample_from_json(const ToleranceSet& set, const nlohmann::json& j,
                              const std::string& source);

//! The whole study: header, spec, yield, the worst samples (most failing first, kept with their
//! deviations and values so `--sample K` reruns one), every sample by index.
nlohmann::json study_json(const ToleranceSet& set, const nlohmann::json& header, const Spec& spec,
                          const std::vector<SampleResult>& samples, std::size_t worst_count = 10);
std::string study_csv(const ToleranceSet& set, const Spec& spec,
                      const std::vector<SampleResult>& samples);

//! Each tolerance alone at its two extremes, the others at nominal.
struct SensitivityRow {
  std::size_t tolerance = 0;
  SampleResult lo, hi;
  //! The largest |change| of any metric over its nominal value, in %: the sort key; infinite
  //! when the plant at either limit is not valid (it fails any spec).
  double effect_pct = 0.0;
};
//! The deviations to run: [0] all nominal, then per tolerance its minimum and its maximum.
std::vector<std::vector<double>> sensitivity_deviations(const ToleranceSet& set);
//! From the runs of sensitivity_deviations (same order), sorted by effect, largest first.
std::vector<SensitivityRow> sensitivity_table(const ToleranceSet& set,
                                              const std::vector<SampleResult>& runs);
nlohmann::json sensitivity_json(const ToleranceSet& set, const SampleResult& nominal,
                                const std::vector<SensitivityRow>& rows);

//! A figure of the report: its caption and its file, relative to the report.
struct ReportFigure {
  std::string caption, path;
};
//! The report, rendered as tolerance.md and tolerance.html (reproduction/document.hpp): the
//! tolerances, the yield, the sensitivity table with what the calibration absorbed (when run), the
//! worst samples, and the metrics' distributions.
std::vector<reproduction::Block> study_report(const ToleranceSet& set, const nlohmann::json& study,
                                              const std::optional<nlohmann::json>& sensitivity,
                                              const std::vector<ReportFigure>& figures);

}  // namespace piezoshift::tolerance
