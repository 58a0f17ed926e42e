#pragma once
// The report's figures of the paper's experiments, as io::Figure values ready for io::render()
// (gnuplot): what is drawn is decided here, once, for the twin's runs and for bench CSV files.
//
//   step_response_figure   Figure 10: y(t) with the +-band_pct band around y_inf, the step and
//                          settling instants; below it, a zoom of y - y_inf in nm with the
//                          +-band_nm band.
//   linearity_figure       Figure 11: (a) measured vs desired with the zero-end line,
//                          (b) deviations from the zero-end and best-fit lines in nm.
//   repeatability_figure   Figure 12: one histogram per target of z_i - zbar in nm, side by
//                          side, each titled with its e_R (Eq. 9).
#include <span>
#include <string>
#include <vector>

#include "piezoshift/experiments/metrics_linearity.hpp"
#include "piezoshift/experiments/metrics_repeatability.hpp"
#include "piezoshift/experiments/metrics_step_response.hpp"
#include "piezoshift/io/plot.hpp"

namespace piezoshift::experiments {

io::Figure step_response_figure(std::span<const double> t_s, std::span<const double> y_um,
                                const StepResponseMetrics& metrics,
                                const StepResponseOptions& options, std::string title = {});

io::Figure linearity_figure(std::span<const double> desired_um, std::span<const double> measured_um,
                            const LinearityMetrics& metrics, std::string title = {});

struct RepeatabilitySet {
  std::string label;                //!< e.g. "5 um"
  std::vector<double> measured_um;  //!< the n repeated displacements
};

//! Most bins one histogram panel draws.
inline constexpr double kMaxHistogramBins = 500.0;

//! bin_nm, or when spread_nm would need more than kMaxHistogramBins bins of it, the smallest 1, 2
//! or 5 x 10^k nm that needs no more (data spread over microns, e.g. a linearity sweep).
double histogram_bin_nm(double spread_nm, double bin_nm);

//! bin_nm: histogram bin width; 1 nm by default, the XL-80's resolution (paper, Section 4), so
//! the interferometer's quantisation steps fall one per bin; wider (histogram_bin_nm, named on
//! the axis) when the data spread over more than 500 bins.
io::Figure repeatability_figure(std::span<const RepeatabilitySet> sets, double bin_nm = 1.0,
                                std::string title = {});

}  // namespace piezoshift::experiments
