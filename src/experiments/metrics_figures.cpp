#include "piezoshift/experiments/metrics_figures.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

namespace piezoshift::experiments {
namespace {

io::Panel make_panel(std::string title, std::string x_label, std::string y_label, std::string key) {
  io::Panel p;
  p.title = std::move(title);
  p.x_label = std::move(x_label);
  p.y_label = std::move(y_label);
  p.key = std::move(key);
  return p;
}

}  // namespace

io::Figure step_response_figure(std::span<const double> t_s, std::span<const double> y_um,
                                const StepResponseMetrics& m, const StepResponseOptions& o,
                                std::string title) {
  io::Figure f;
  f.title = std::move(title);
  f.rows = 2;
  f.width_px = 900;
  f.height_px = 750;
  const double t0 = t_s.front(), t1 = t_s.back();

  io::Panel top = make_panel("Step response", "time [s]", "displacement [um]", "bottom right");
  const double h_pct = o.band_pct / 100.0 * std::abs(m.step_um);
  top.series.push_back(io::band_series(fmt::format("+-{:g} % of the step", o.band_pct), t0, t1,
                                       m.final_um - h_pct, m.final_um + h_pct));
  top.series.push_back(io::line_series("measured", t_s, y_um));
  top.markers.push_back({true, o.step_time_s, "step"});
  if (std::isfinite(m.settling_time_pct_s))
    top.markers.push_back(
        {true, o.step_time_s + m.settling_time_pct_s,
         fmt::format("settled +-{:g} %: {:.4g} s", o.band_pct, m.settling_time_pct_s)});

  io::Panel zoom = make_panel("Near the final value", "time [s]", "y - y_final [nm]", "top right");
  std::vector<double> dev_nm(y_um.size());
  for (std::size_t i = 0; i < y_um.size(); ++i)
    dev_nm[i] = 1000.0 * (y_um[i] - m.final_um);
  zoom.series.push_back(io::band_series(fmt::format("+-{:g} nm", o.band_nm), t0, t1, -o.band_nm,
                                        o.band_nm, "#ff7f0e"));
  zoom.series.push_back(io::line_series("measured", t_s, dev_nm));
  zoom.y_range = std::pair{-5.0 * o.band_nm, 5.0 * o.band_nm};
  if (std::isfinite(m.settling_time_abs_s))
    zoom.markers.push_back(
        {true, o.step_time_s + m.settling_time_abs_s,
         fmt::format("settled +-{:g} nm: {:.4g} s", o.band_nm, m.settling_time_abs_s)});
  f.panels = {std::move(top), std::move(zoom)};
  return f;
}

io::Figure linearity_figure(std::span<const double> desired_um, std::span<const double> measured_um,
                            const LinearityMetrics& m, std::string title) {
  io::Figure f;
  f.title = std::move(title);
  f.rows = 2;
  f.width_px = 800;
  f.height_px = 800;
  io::Panel curve = make_panel("(a) displacement", "desired displacement [um]",
                               "measured displacement [um]", "top left");
  const double x0 = desired_um.front(), x1 = desired_um.back();
  const std::vector<double> lx{x0, x1};
  const std::vector<double> ly{m.zero_end_intercept_um + m.zero_end_slope * x0,
                               m.zero_end_intercept_um + m.zero_end_slope * x1};
  curve.series.push_back(io::line_series("zero-end line", lx, ly, "#7f7f7f"));
  io::Series pts = io::point_series("measured", desired_um, measured_um);
  pts.style = io::SeriesStyle::kLinesPoints;
  curve.series.push_back(std::move(pts));

  io::Panel err =
      make_panel(fmt::format("(b) linearity error: zero-end {:.3f} %, best-fit {:.3f} %",
                             m.linearity_zero_end_pct, m.linearity_best_fit_pct),
                 "desired displacement [um]", "deviation [nm]", "top right");
  std::vector<double> d0(m.n), d1(m.n);
  for (std::size_t i = 0; i < m.n; ++i) {
    d0[i] = 1000.0 * m.deviation_zero_end_um[i];
    d1[i] = 1000.0 * m.deviation_best_fit_um[i];
  }
  io::Series s0 = io::line_series("from the zero-end line", desired_um, d0);
  s0.style = io::SeriesStyle::kLinesPoints;
  io::Series s1 = io::line_series("from the best-fit line", desired_um, d1);
  s1.style = io::SeriesStyle::kLinesPoints;
  err.series = {std::move(s0), std::move(s1)};
  err.markers.push_back({false, 0.0, ""});
  f.panels = {std::move(curve), std::move(err)};
  return f;
}

double histogram_bin_nm(double spread_nm, double bin_nm) {
  if (!(spread_nm / bin_nm > kMaxHistogramBins))
    return bin_nm;
  const double least = spread_nm / kMaxHistogramBins;
  const double decade = std::pow(10.0, std::floor(std::log10(least)));
  for (const double m : {1.0, 2.0, 5.0}) {
    if (m * decade >= least)
      return m * decade;
  }
  return 10.0 * decade;
}

io::Figure repeatability_figure(std::span<const RepeatabilitySet> sets, double bin_nm,
                                std::string title) {
  if (sets.empty())
    throw MetricsError("repeatability figure: no data sets");
  io::Figure f;
  f.title = std::move(title);
  f.cols = static_cast<int>(sets.size());
  f.width_px = 450 * f.cols;
  f.height_px = 450;
  for (const RepeatabilitySet& s : sets) {
    const RepeatabilityMetrics r = repeatability_metrics(s.measured_um);
    std::vector<double> dev_nm(s.measured_um.size());
    for (std::size_t i = 0; i < dev_nm.size(); ++i)
      dev_nm[i] = 1000.0 * (s.measured_um[i] - r.mean_um);
    const double bin = histogram_bin_nm(1000.0 * (r.max_um - r.min_um), bin_nm);
    io::Panel p = make_panel(
        fmt::format("{}: e_R = {:.2f} nm (n = {})", s.label, r.repeatability_nm, r.n),
        bin == bin_nm ? fmt::format("z - mean ({:.4f} um) [nm]", r.mean_um)
                      : fmt::format("z - mean ({:.4f} um) [nm], bins of {:g} nm", r.mean_um, bin),
        "count", "off");
    p.series.push_back(io::histogram_series("", dev_nm, bin));
    // Counts start at zero, or the bars' heights mislead.
    const auto& counts = p.series.back().y;
    const double top = counts.empty() ? 1.0 : *std::max_element(counts.begin(), counts.end());
    p.y_range = std::pair{0.0, 1.1 * top};
    f.panels.push_back(std::move(p));
  }
  return f;
}

}  // namespace piezoshift::experiments
