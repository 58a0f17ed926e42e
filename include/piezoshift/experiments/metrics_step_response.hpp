#pragma once
// Step-response metrics of a recorded displacement y(t) after a step commanded at t_s (paper,
// Section 4.1 and Figure 10: an 11 um step settles in less than 0.3 s).
//
// Levels: y0 = mean of the samples before t_s (the first sample if there are none);
//         y_inf = mean of the last final_window_fraction of the samples (or both given).
//         step = y_inf - y0 (either sign); g(t) = (y(t) - y0) / step goes from 0 to 1.
// Rise time      t_90 - t_10: first instants at or after t_s where g reaches 0.1 and then 0.9.
// Overshoot      100 max(0, max_{t >= t_s} g(t) - 1)            [% of the step]
// Settling time  last instant at which |y(t) - y_inf| > h, measured from t_s, where
//                h = band_pct/100 |step| (the "+-2 %" band) or h = band_nm / 1000 (the
//                "+-10 nm" band); 0 when y is inside the band from t_s on, +inf when the last
//                sample is still outside (not settled within the record).
// Crossing instants are interpolated linearly between the two samples around the crossing.
//
// Robustness to noise: the levels y0 and y_inf are averages, not single samples; and before the
// level crossings and the band test, y is passed through a centred running median of
// median_window samples (5 by default, 5 ms at the paper's 1 kHz), shrunk symmetrically at the
// ends of the record. A median removes isolated spikes (up to (w-1)/2 in a row) but leaves a
// monotone stretch of the record exactly as it was, so it neither delays a clean edge nor changes
// a noise-free result; set median_window = 1 to use the raw samples. The peak (overshoot) is
// taken from the raw samples, because a median clips a sampled peak (the third largest of five
// samples) while nm noise moves an overshoot in % of a um step by only noise / step (1 nm on
// 11 um: 0.01 %); a gross spike after the step therefore shows as overshoot. A noise level that
// is not small compared with the band still makes the settling time late, as it should: the
// response is then not always inside the band.
#include <cstddef>
#include <limits>
#include <span>
#include <vector>

#include "piezoshift/experiments/metrics_error.hpp"

namespace piezoshift::experiments {

struct StepResponseOptions {
  double step_time_s = 0.0;  //!< t_s, when the step was commanded [s]
  //! y0 [um]; NaN: the mean of the samples before t_s
  double initial_um = std::numeric_limits<double>::quiet_NaN();
  //! y_inf [um]; NaN: the mean of the last final_window_fraction of the samples
  double final_um = std::numeric_limits<double>::quiet_NaN();
  double final_window_fraction = 0.1;  //!< in (0, 1]
  double band_pct = 2.0;               //!< relative settling band, +- % of |step|
  double band_nm = 10.0;               //!< absolute settling band, +- nm
  std::size_t median_window = 5;       //!< odd, >= 1; 1: no filtering [samples]
};

struct StepResponseMetrics {
  double initial_um = 0.0;           //!< y0
  double final_um = 0.0;             //!< y_inf
  double step_um = 0.0;              //!< y_inf - y0
  double t10_s = 0.0;                //!< absolute time of the 10 % crossing (NaN if never reached)
  double t90_s = 0.0;                //!< absolute time of the 90 % crossing (NaN if never reached)
  double rise_time_s = 0.0;          //!< t90 - t10 (NaN if either is missing)
  double peak_um = 0.0;              //!< extreme of y in the step's direction, t >= t_s
  double peak_time_s = 0.0;          //!< absolute time of the peak
  double overshoot_pct = 0.0;        //!< [% of |step|]
  double settling_time_pct_s = 0.0;  //!< to +- band_pct, from t_s (+inf: not settled)
  double settling_time_abs_s = 0.0;  //!< to +- band_nm, from t_s (+inf: not settled)
  double band_pct = 0.0;             //!< the bands used, echoed for reports
  double band_nm = 0.0;
};

//! Needs t_s strictly increasing, equal sizes, all finite, at least 3 samples at or after
//! step_time_s and a non-zero step; otherwise MetricsError.
StepResponseMetrics step_response_metrics(std::span<const double> t_s, std::span<const double> y_um,
                                          const StepResponseOptions& options = {});

//! Longest running median: 1001 samples (1 s at the paper's 1 kHz); the cost is n x window.
inline constexpr std::size_t kMaxMedianWindow = 1001;

//! The centred running median used above (exposed for plots and tests). window odd, in
//! [1, kMaxMedianWindow]; otherwise MetricsError.
std::vector<double> running_median(std::span<const double> y, std::size_t window);

}  // namespace piezoshift::experiments
