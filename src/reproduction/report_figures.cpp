#include "report_figures.hpp"

#include <algorithm>
#include <cmath>
#include <complex>

#include <fmt/core.h>

#include "piezoshift/experiments/metrics_figures.hpp"
#include "piezoshift/experiments/paper_experiments.hpp"
#include "piezoshift/io/plot.hpp"
#include "piezoshift/reproduction/figure_format.hpp"

namespace piezoshift::reproduction::detail {

namespace fs = std::filesystem;

// The lambda/8 step of both controllers on the true plate's 1 ms exposure means, with the +-1 nm
// band around the target over the whole record; below, the same around the target at nm scale,
// where the hold jitter of the two controllers differs.
io::Figure phase_step_figure(const ReproductionResult& r) {
  const auto& a = r.phase_step;
  const auto& b = r.oracle.phase_step;
  const double tol = r.schedule.phase_step.tolerance_nm;
  io::Figure f;
  f.title = fmt::format("Phase step of λ/8 = {:.1f} nm (twin, true plate, {:g} ms exposures)",
                        a.step_nm, 1e3 * r.schedule.phase_step.exposure_s);
  f.rows = 2;
  f.width_px = 800;
  f.height_px = 760;
  const auto name = [](const char* who, const experiments::PhaseStepResult& p) {
    return fmt::format("{}: settled {}, hold jitter {:.2f} nm rms", who,
                       std::isfinite(p.settling_time_s)
                           ? fmt::format("{:.1f} ms", 1e3 * p.settling_time_s)
                           : std::string("never"),
                       p.hold_jitter_nm_rms);
  };
  io::Panel whole, near;
  whole.title = "(a) the step";
  near.title = fmt::format("(b) around the target: ±{:g} nm band", tol);
  whole.x_label = near.x_label = "time from the step command [s]";
  whole.y_label = "exposure mean − level before [nm]";
  near.y_label = "exposure mean − target [nm]";
  const std::vector<const experiments::PhaseStepResult*> runs{&a, &b};
  const char* const who[] = {"paper's controller", "oracle"};
  double t1 = 0.0;
  for (const auto* p : runs)
    t1 = p->time_s.empty() ? t1 : std::max(t1, p->time_s.back());
  whole.x_range = near.x_range = std::pair{0.0, t1};
  whole.series.push_back(
      io::band_series(fmt::format("±{:g} nm", tol), 0.0, t1, a.step_nm - tol, a.step_nm + tol));
  near.series.push_back(io::band_series(fmt::format("±{:g} nm", tol), 0.0, t1, -tol, tol));
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const auto& p = *runs[k];
    std::vector<double> err(p.exposure_mean_nm);
    for (double& v : err)
      v -= p.step_nm;
    whole.series.push_back(io::line_series(name(who[k], p), p.time_s, p.exposure_mean_nm));
    io::Series e = io::line_series("", p.time_s, err);
    near.series.push_back(std::move(e));
    if (std::isfinite(p.settling_time_s))
      near.markers.push_back(
          {.vertical = true,
           .at = p.settling_time_s,
           .label = fmt::format("{} settled: {:.1f} ms", k == 0 ? "paper" : "oracle",
                                1e3 * p.settling_time_s),
           .label_at = k == 0 ? 0.9 : 0.1});
  }
  whole.key = "below";
  near.key = "off";
  near.y_range = std::pair{-4.0 * tol, 4.0 * tol};
  f.panels = {std::move(whole), std::move(near)};
  f.caption = fmt::format(
      "λ/8 phase step: paper's controller settles to ±{0:g} nm in {1}, oracle in {2}; hold jitter "
      "{3:.2f} against {4:.2f} nm rms.",
      tol, format_figure(a.settling_time_s, "s"), format_figure(b.settling_time_s, "s"),
      a.hold_jitter_nm_rms, b.hold_jitter_nm_rms);
  return f;
}

namespace {

// |L| and arg L of one channel's loop, phase unwrapped, 401 points from 0.1 Hz to Nyquist.
struct LoopCurve {
  std::vector<double> hz, db, deg;
};

LoopCurve loop_curve(const InnerLoopAnalysis& a, std::size_t channel) {
  LoopCurve c;
  const double nyquist = 0.5 / a.sample_time_s;
  double unwrapped = 0.0;
  for (int k = 0; k <= 400; ++k) {
    const double hz = 0.1 * std::pow(nyquist / 0.1, k / 400.0);
    const std::complex<double> l =
        calibration::loop_frequency_response(a.plant.channel[channel], a.pid, hz);
    double d = std::arg(l) * 180.0 / 3.14159265358979323846;
    if (!c.deg.empty()) {
      while (d - unwrapped > 180.0)
        d -= 360.0;
      while (d - unwrapped < -180.0)
        d += 360.0;
    }
    unwrapped = d;
    c.hz.push_back(hz);
    c.db.push_back(20.0 * std::log10(std::abs(l)));
    c.deg.push_back(d);
  }
  return c;
}

}  // namespace

// Bode plot of the calibrated PID's loop on each identified plant, at each loop rate: one colour
// per rate, one dash per actuator, one legend (below the phase); the worst channel's gain and
// phase margins marked at their crossover frequencies.
io::Figure inner_loop_figure(const ReproductionResult& r) {
  io::Figure f;
  f.title = "Inner loop L = PID × identified plant (twin, through the shipping tick)";
  f.rows = 2;
  f.width_px = 800;
  f.height_px = 800;
  io::Panel mag, ph;
  mag.title = "(a) gain";
  ph.title = "(b) phase";
  mag.x_label = ph.x_label = "frequency [Hz]";
  mag.y_label = "|L| [dB]";
  ph.y_label = "arg L [°]";
  mag.x_log = ph.x_log = true;
  mag.key = "below";
  ph.key = "below";
  mag.markers.push_back({.vertical = false, .at = 0.0, .label = "0 dB", .label_at = 0.02});
  ph.markers.push_back({.vertical = false, .at = -180.0, .label = "−180°", .label_at = 0.02});
  const char* const rate_colour[] = {"#0072B2", "#D55E00", "#009E73"};
  const char* const actuator_dash[] = {"solid", "(8,4)", "(2,3)"};
  std::size_t rate = 0;
  for (const InnerLoopAnalysis& a : r.inner_loop) {
    if (!a.validity.valid)
      continue;
    const std::string colour = rate_colour[rate % 3];
    const std::string khz = fmt::format("{:g} kHz", 1e-3 / a.sample_time_s);
    for (std::size_t i = 0; i < 3; ++i) {
      const LoopCurve c = loop_curve(a, i);
      io::Series m = io::line_series("", c.hz, c.db, colour);
      io::Series p =
          io::line_series(fmt::format("{}, actuator {}", khz, i + 1), c.hz, c.deg, colour);
      m.dash = p.dash = actuator_dash[i];
      mag.series.push_back(std::move(m));
      ph.series.push_back(std::move(p));
    }
    const runtime::StabilityMargins w = a.worst();
    if (std::isfinite(w.gain_margin_dB) && std::isfinite(w.phase_crossover_Hz)) {
      const std::vector<double> x{w.phase_crossover_Hz}, y{-w.gain_margin_dB};
      io::Series gm = io::point_series(fmt::format("{}: gain margin {:.1f} dB at {:.0f} Hz", khz,
                                                   w.gain_margin_dB, w.phase_crossover_Hz),
                                       x, y, colour);
      mag.series.push_back(std::move(gm));
    }
    if (std::isfinite(w.phase_margin_deg) && std::isfinite(w.gain_crossover_Hz)) {
      const std::vector<double> x{w.gain_crossover_Hz}, y{-180.0 + w.phase_margin_deg};
      io::Series pm = io::point_series(fmt::format("{}: phase margin {:.1f}° at {:.0f} Hz", khz,
                                                   w.phase_margin_deg, w.gain_crossover_Hz),
                                       x, y, colour);
      ph.series.push_back(std::move(pm));
    }
    ++rate;
  }
  f.panels = {std::move(mag), std::move(ph)};
  f.caption =
      "Bode plot of the inner loop per loop rate and actuator; dots: the worst channel's gain "
      "margin (at the phase crossover) and phase margin (at the gain crossover).";
  return f;
}

// Figures 10 to 12 and the phase step, and the inner loop's Bode plot when a loop rate was
// analysed; returns whether it was.
bool write_figures(const ReproductionResult& r, const fs::path& dir, ReportFiles& files) {
  experiments::StepResponseOptions so;
  so.band_pct = r.step.metrics.band_pct;
  so.band_nm = r.step.metrics.band_nm;
  io::Figure f10 = experiments::step_response_figure(
      r.step.time_s, r.step.measured_um, r.step.metrics, so,
      fmt::format("Step response to {:g} µm (twin, interferometer dynamic mode, 1 kHz)",
                  r.step.desired_um.back()));
  io::Figure f11 = experiments::linearity_figure(r.linearity.desired_um, r.linearity.measured_um,
                                                 r.linearity.metrics, "Linearity (twin)");
  const std::vector<experiments::RepeatabilitySet> sets{{"5 µm", r.repeat_5um.measured_um},
                                                        {"10 µm", r.repeat_10um.measured_um}};
  io::Figure f12 = experiments::repeatability_figure(sets, 1.0, "Repeatability (twin)");
  io::Figure fps = phase_step_figure(r);
  for (const auto& [fig, stem] :
       {std::pair{&f10, "fig10_step_response"}, std::pair{&f11, "fig11_linearity"},
        std::pair{&f12, "fig12_repeatability"}, std::pair{&fps, "phase_step"}}) {
    const io::PlotFiles pf = io::render(*fig, dir / stem);
    files.figures.push_back(*pf.png);
    files.captions.push_back(fig->caption);
  }
  const bool any_loop = std::any_of(r.inner_loop.begin(), r.inner_loop.end(),
                                    [](const InnerLoopAnalysis& a) { return a.validity.valid; });
  if (any_loop) {
    const io::Figure bode = inner_loop_figure(r);
    files.figures.push_back(*io::render(bode, dir / "inner_loop_bode").png);
    files.captions.push_back(bode.caption);
  }
  return any_loop;
}

}  // namespace piezoshift::reproduction::detail
