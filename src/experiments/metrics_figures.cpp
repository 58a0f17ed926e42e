#include "piezoshift/experiments/metrics_figures.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include <fmt/core.h>

namespace piezoshift::experiments {
namespace {

constexpr double kPi = 3.14159265358979323846;

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
  f.width_px = 800;
  f.height_px = 720;
  // The transient lasts tens of ms of a record of a second: both panels show the step and its
  // settling, 2.5 times the longer settling time (the whole record when it never settled).
  const double t_step = o.step_time_s;
  const double settle = std::max(m.settling_time_pct_s, m.settling_time_abs_s);
  const double t0 = t_s.front(), t1 = t_s.back();
  const double span = std::isfinite(settle) && settle > 0.0 ? 2.5 * settle : t1 - t_step;
  const std::pair<double, double> window{std::max(t0, t_step - 0.1 * span),
                                         std::min(t1, t_step + span)};
  const std::string settled_pct =
      std::isfinite(m.settling_time_pct_s)
          ? fmt::format("settled to ±{:g} %: {:.3f} s", o.band_pct, m.settling_time_pct_s)
          : fmt::format("not settled to ±{:g} %", o.band_pct);
  const std::string settled_abs =
      std::isfinite(m.settling_time_abs_s)
          ? fmt::format("settled to ±{:g} nm: {:.3f} s", o.band_nm, m.settling_time_abs_s)
          : fmt::format("not settled to ±{:g} nm", o.band_nm);

  io::Panel top = make_panel(fmt::format("(a) the step, final value {:.4f} µm", m.final_um),
                             "time [s]", "displacement [µm]", "below");
  const double h_pct = o.band_pct / 100.0 * std::abs(m.step_um);
  top.series.push_back(io::band_series(fmt::format("±{:g} % of the step", o.band_pct), t0, t1,
                                       m.final_um - h_pct, m.final_um + h_pct));
  top.series.push_back(io::line_series("measured", t_s, y_um));
  top.x_range = window;
  top.markers.push_back({.vertical = true, .at = t_step, .label = "step", .label_at = 0.55});
  if (std::isfinite(m.settling_time_pct_s))
    top.markers.push_back({.vertical = true,
                           .at = t_step + m.settling_time_pct_s,
                           .label = settled_pct,
                           .label_at = 0.3});

  io::Panel zoom = make_panel(fmt::format("(b) near the final value: {}", settled_abs), "time [s]",
                              "y − y_final [nm]", "below");
  std::vector<double> dev_nm(y_um.size());
  for (std::size_t i = 0; i < y_um.size(); ++i)
    dev_nm[i] = 1000.0 * (y_um[i] - m.final_um);
  zoom.series.push_back(io::band_series(fmt::format("±{:g} nm", o.band_nm), t0, t1, -o.band_nm,
                                        o.band_nm, "#E69F00"));
  zoom.series.push_back(io::line_series("measured", t_s, dev_nm));
  zoom.x_range = window;
  zoom.y_range = std::pair{-5.0 * o.band_nm, 5.0 * o.band_nm};
  if (std::isfinite(m.settling_time_pct_s))
    zoom.markers.push_back(
        {.vertical = true,
         .at = t_step + m.settling_time_pct_s,
         .label = fmt::format("±{:g} %: {:.3f} s", o.band_pct, m.settling_time_pct_s),
         .label_at = 0.88});
  if (std::isfinite(m.settling_time_abs_s))
    zoom.markers.push_back(
        {.vertical = true,
         .at = t_step + m.settling_time_abs_s,
         .label = fmt::format("±{:g} nm: {:.3f} s", o.band_nm, m.settling_time_abs_s),
         .label_at = 0.12});
  f.panels = {std::move(top), std::move(zoom)};
  f.caption = fmt::format("Step response: {}; {}; record {:.2f} s, zoomed on the transient.",
                          settled_pct, settled_abs, t1 - t0);
  return f;
}

namespace {

// The y range of curves in nm with a margin, so that no point sits on the frame.
std::pair<double, double> padded_range(std::span<const double> a, std::span<const double> b) {
  double lo = 0.0, hi = 0.0;
  for (const auto& v : {a, b}) {
    for (const double x : v) {
      lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
  }
  const double pad = std::max(0.15 * (hi - lo), 0.5);
  return {lo - pad, hi + pad};
}

}  // namespace

io::Figure linearity_figure(std::span<const double> desired_um, std::span<const double> measured_um,
                            const LinearityMetrics& m, std::string title) {
  io::Figure f;
  f.title = std::move(title);
  f.rows = 2;
  f.width_px = 800;
  f.height_px = 760;
  // (a) measured - desired: at nm scale, where the gain error and the zero-end line show (the
  // measured-against-desired curve is a straight 0-11 µm diagonal that shows neither).
  io::Panel curve = make_panel("(a) measured − desired, and the zero-end line",
                               "desired displacement [µm]", "measured − desired [nm]", "below");
  const double x0 = desired_um.front(), x1 = desired_um.back();
  std::vector<double> err_nm(desired_um.size()), line_nm(desired_um.size());
  for (std::size_t i = 0; i < desired_um.size(); ++i) {
    err_nm[i] = 1000.0 * (measured_um[i] - desired_um[i]);
    line_nm[i] =
        1000.0 * (m.zero_end_intercept_um + m.zero_end_slope * desired_um[i] - desired_um[i]);
  }
  io::Series pts = io::point_series("measured", desired_um, err_nm);
  pts.style = io::SeriesStyle::kLinesPoints;
  curve.series.push_back(std::move(pts));
  // Drawn after the data, dashed, so that it shows over the points it joins.
  io::Series zero_end = io::line_series(
      fmt::format("zero-end line (slope {:.5f})", m.zero_end_slope), desired_um, line_nm);
  zero_end.line_width = 2.0;
  curve.series.push_back(std::move(zero_end));
  curve.x_range = std::pair{x0, x1};
  curve.y_range = padded_range(err_nm, line_nm);

  io::Panel err =
      make_panel(fmt::format("(b) linearity error: zero-end {:.3f} %, best-fit {:.3f} %",
                             m.linearity_zero_end_pct, m.linearity_best_fit_pct),
                 "desired displacement [µm]", "deviation [nm]", "below");
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
  err.markers.push_back({.vertical = false, .at = 0.0, .label = ""});
  err.x_range = std::pair{x0, x1};
  err.y_range = padded_range(d0, d1);
  f.panels = {std::move(curve), std::move(err)};
  f.caption = fmt::format(
      "Linearity over {:g} to {:g} µm: zero-end {:.3f} %, best-fit {:.3f} % of the range.", x0, x1,
      m.linearity_zero_end_pct, m.linearity_best_fit_pct);
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

namespace {

// The normal density with standard deviation sigma_nm, scaled to counts of n values in bins of
// bin_nm, over +-4 sigma (at least the histogram's span).
io::Series gaussian_series(double sigma_nm, std::size_t n, double bin_nm, double lo_nm,
                           double hi_nm) {
  std::vector<double> x, y;
  const double a = std::min(lo_nm, -4.0 * sigma_nm), b = std::max(hi_nm, 4.0 * sigma_nm);
  const double scale = static_cast<double>(n) * bin_nm / (sigma_nm * std::sqrt(2.0 * kPi));
  for (int k = 0; k <= 200; ++k) {
    const double v = a + (b - a) * k / 200.0;
    x.push_back(v);
    y.push_back(scale * std::exp(-0.5 * v * v / (sigma_nm * sigma_nm)));
  }
  io::Series s = io::line_series("normal density, σ = e_R", x, y, "#D55E00");
  s.line_width = 2.0;
  return s;
}

}  // namespace

io::Figure repeatability_figure(std::span<const RepeatabilitySet> sets, double bin_nm,
                                std::string title) {
  if (sets.empty())
    throw MetricsError("repeatability figure: no data sets");
  io::Figure f;
  f.title = title.empty() ? std::string("e_R: sample standard deviation σ of z_i (Eq. 9)")
                          : title + " — e_R: sample standard deviation σ of z_i (Eq. 9)";
  f.cols = static_cast<int>(sets.size());
  f.width_px = 420 * f.cols;
  f.height_px = 460;
  std::string caption;
  for (const RepeatabilitySet& s : sets) {
    const RepeatabilityMetrics r = repeatability_metrics(s.measured_um);
    std::vector<double> dev_nm(s.measured_um.size());
    for (std::size_t i = 0; i < dev_nm.size(); ++i)
      dev_nm[i] = 1000.0 * (s.measured_um[i] - r.mean_um);
    const double bin = histogram_bin_nm(1000.0 * (r.max_um - r.min_um), bin_nm);
    io::Panel p = make_panel(
        fmt::format("{}: e_R = {:.2f} nm (n = {})", s.label, r.repeatability_nm, r.n),
        bin == bin_nm
            ? fmt::format("z − mean [nm]; mean {:.4f} µm", r.mean_um)
            : fmt::format("z − mean [nm]; mean {:.4f} µm, bins of {:g} nm", r.mean_um, bin),
        "count", "below");
    p.series.push_back(io::histogram_series(
        bin == bin_nm ? fmt::format("z_i, bins of {:g} nm", bin) : std::string("z_i"), dev_nm,
        bin));
    // Counts start at zero, or the bars' heights mislead.
    const auto& counts = p.series.back().y;
    const double top = counts.empty() ? 1.0 : *std::max_element(counts.begin(), counts.end());
    p.y_range = std::pair{0.0, 1.25 * top};
    if (r.repeatability_nm > 0.0) {
      const double lo = 1000.0 * (r.min_um - r.mean_um) - bin;
      const double hi = 1000.0 * (r.max_um - r.mean_um) + bin;
      p.series.push_back(gaussian_series(r.repeatability_nm, r.n, bin, lo, hi));
      p.markers.push_back(
          {.vertical = true, .at = -r.repeatability_nm, .label = "−1 σ", .label_at = 0.9});
      p.markers.push_back({.vertical = true,
                           .at = r.repeatability_nm,
                           .label = fmt::format("+1 σ = {:.2f} nm", r.repeatability_nm),
                           .label_at = 0.9});
    }
    caption += fmt::format("{}{}: e_R = {:.2f} nm", caption.empty() ? "" : ", ", s.label,
                           r.repeatability_nm);
    f.panels.push_back(std::move(p));
  }
  f.caption = "Repeatability histograms with the normal density of σ = e_R: " + caption + ".";
  return f;
}

}  // namespace piezoshift::experiments
