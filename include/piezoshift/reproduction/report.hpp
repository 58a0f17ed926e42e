#pragma once
// The report of a reproduction, written into one folder:
//   report.md, report.html    Table 4 beside the paper's row and the two commercial rows, the
//                             calibration (gains and their scores, A and p beside the paper's),
//                             the figures, and what the twin cannot say
//   fig10_step_response.png   Figure 10   (gnuplot; each with its .gp script and .dat data)
//   fig11_linearity.png       Figure 11
//   fig12_repeatability.png   Figure 12
//   summary.json              summary_json()
//   calibration.toml          the calibrated controller (calibration_file.hpp), written atomically
//   *.csv                     every experiment's data, in the formats `piezoshift fit` and
//                             `piezoshift analyze` read, so the numbers can be re-derived
// Throws core::InputError when the folder cannot be written and io::PlotError when gnuplot fails.
#include <filesystem>
#include <string>
#include <vector>

#include "piezoshift/reproduction/reproduction.hpp"

namespace piezoshift::reproduction {

struct ReportFiles {
  std::filesystem::path markdown;
  std::filesystem::path html;
  std::vector<std::filesystem::path> figures;  //!< the PNGs (an SVG beside each)
  std::vector<std::string> captions;           //!< per figure, its one-line caption (empty: none)
  std::vector<std::filesystem::path> data;     //!< CSV, JSON and TOML files
};

//! config_label says where the configuration came from (a path, or the built-in defaults).
ReportFiles write_report(const ReproductionResult& result, const std::filesystem::path& dir,
                         const std::string& config_label);

}  // namespace piezoshift::reproduction
