#include "piezoshift/reproduction/report.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <fstream>
#include <system_error>

#include <fmt/core.h>

#include "piezoshift/calibration/calibration_file.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/experiments/metrics_figures.hpp"
#include "piezoshift/experiments/paper_experiments.hpp"
#include "piezoshift/io/atomic_file.hpp"
#include "piezoshift/io/csv_writer.hpp"
#include "piezoshift/io/plot.hpp"
#include "piezoshift/reproduction/document.hpp"
#include "piezoshift/reproduction/figure_format.hpp"
#include "piezoshift/reproduction/measurement_report.hpp"
#include "piezoshift/reproduction/paper_bands.hpp"
#include "piezoshift/reproduction/summary.hpp"

#include "report_figures.hpp"

namespace piezoshift::reproduction {
namespace {

namespace fs = std::filesystem;

// A figure with its caption printed under it ("Figure 10: ..."), as a paper prints one.
void figure(Document& doc, const std::string& name, const std::string& file,
            const std::string& caption) {
  doc.image(name, file);
  if (!caption.empty())
    doc.paragraph(name + ": " + caption);
}

std::string matrix_text(const control::Mat3& a) {
  std::string s;
  for (const auto& row : a)
    s += fmt::format("[{:8.4f} {:8.4f} {:8.4f}]\n", row[0], row[1], row[2]);
  s.pop_back();
  return s;
}

std::string poly_text(const control::CubicPolynomial& p) {
  return fmt::format("p3 = {:.4e}, p2 = {:.4e}, p1 = {:.4f}, p0 = {:.4f} µm", p.p3, p.p2, p.p1,
                     p.p0);
}

std::vector<std::string> trial_row(const std::string& label, const calibration::PidTrial& t) {
  return {label,
          fmt::format("{:g} / {:g} / {:g}", t.gains.kp, t.gains.ki, t.gains.kd),
          format_figure(t.worst.overshoot_pct, "%"),
          format_figure(t.worst.settling_time_s, "s"),
          format_figure(t.worst.steady_state_error_nm, "nm"),
          t.acceptable ? "yes" : "no"};
}

void write_data(const ReproductionResult& r, const fs::path& dir, ReportFiles& files) {
  auto csv = [&](const std::string& name, std::vector<std::string> columns, int decimals) {
    files.data.push_back(dir / name);
    return std::make_unique<io::CsvWriter>((dir / name).string(), std::move(columns), decimals);
  };
  {
    auto w = csv("step_response.csv", {"t_s", "zd_um", "measured_um"}, 6);
    for (std::size_t k = 0; k < r.step.time_s.size(); ++k) {
      w->row({r.step.time_s[k], r.step.desired_um[k], r.step.measured_um[k]});
    }
    w->close();
  }
  {
    auto w = csv("linearity.csv", {"zd_um", "measured_um"}, 6);
    for (std::size_t k = 0; k < r.linearity.desired_um.size(); ++k) {
      w->row({r.linearity.desired_um[k], r.linearity.measured_um[k]});
    }
    w->close();
    auto s = csv("linearity_samples.csv", {"t_s", "zd_um", "measured_um"}, 6);
    for (std::size_t k = 0; k < r.linearity.sample_time_s.size(); ++k) {
      s->row({r.linearity.sample_time_s[k], r.linearity.sample_desired_um[k],
              r.linearity.sample_measured_um[k]});
    }
    s->close();
  }
  for (const auto& [name, lin] :
       {std::pair{"linearity_grid.csv", &r.linearity_grid},
        std::pair{"linearity_down.csv", &r.linearity_down},
        std::pair{"linearity_without_cubic.csv", &r.linearity_without_cubic},
        std::pair{"oracle_linearity.csv", &r.oracle.linearity}}) {
    auto w = csv(name, {"zd_um", "measured_um"}, 6);
    for (std::size_t k = 0; k < lin->desired_um.size(); ++k)
      w->row({lin->desired_um[k], lin->measured_um[k]});
    w->close();
  }
  {
    // Both controllers' records have the same ticks (same schedule and sample time).
    auto w = csv("phase_step.csv", {"t_s", "paper_nm", "oracle_nm"}, 6);
    const auto& a = r.phase_step;
    const auto& b = r.oracle.phase_step;
    for (std::size_t k = 0; k < std::min(a.time_s.size(), b.time_s.size()); ++k)
      w->row({a.time_s[k], a.exposure_mean_nm[k], b.exposure_mean_nm[k]});
    w->close();
  }
  for (const auto* rep : {&r.repeat_5um, &r.repeat_10um}) {
    auto w =
        csv(fmt::format("repeatability_{:g}um.csv", rep->target_um), {"move", "measured_um"}, 6);
    for (std::size_t k = 0; k < rep->measured_um.size(); ++k) {
      w->row({static_cast<double>(k + 1), rep->measured_um[k]});
    }
    w->close();
  }
  {
    auto w = csv("travel_range.csv", {"zd_um", "measured_um", "saturated_mask"}, 6);
    for (std::size_t k = 0; k < r.travel.desired_um.size(); ++k) {
      w->row({r.travel.desired_um[k], r.travel.measured_um[k],
              static_cast<double>(r.travel.saturated_mask[k])});
    }
    w->close();
  }
  {
    const auto& m = r.calibration.matrix;
    auto w = csv("matrix_poses.csv", {"s1_um", "s2_um", "s3_um", "z1_um", "z2_um", "z3_um"}, 6);
    for (std::size_t k = 0; k < m.ds_um.size(); ++k) {
      w->row({m.ds_um[k][0], m.ds_um[k][1], m.ds_um[k][2], m.dz_um[k][0], m.dz_um[k][1],
              m.dz_um[k][2]});
    }
    w->close();
  }
  {
    const auto& p = r.calibration.polynomial;
    auto w = csv("polynomial_points.csv", {"command_um", "measured_um"}, 6);
    for (std::size_t k = 0; k < p.command_um.size(); ++k)
      w->row({p.command_um[k], p.measured_um[k]});
    w->close();
  }
  {
    auto w = csv("pid_trials.csv",
                 {"kp", "ki", "kd", "worst_overshoot_pct", "worst_settling_time_s",
                  "worst_steady_state_error_nm", "acceptable"},
                 6);
    for (const auto& t : r.calibration.pid.trials) {
      w->row({t.gains.kp, t.gains.ki, t.gains.kd, t.worst.overshoot_pct, t.worst.settling_time_s,
              t.worst.steady_state_error_nm, t.acceptable ? 1.0 : 0.0});
    }
    w->close();
  }
  write_text(dir / "summary.json", summary_json(r).dump(2) + "\n");
  files.data.push_back(dir / "summary.json");
  calibration::write_calibration_file(
      (dir / "calibration.toml").string(), r.calibration.controller,
      fmt::format(
          "piezoshift calibration, identified on the digital twin by `piezoshift reproduce`\n"
          "seed {}, {} schedule, PID gains: {}",
          r.options.seed, r.options.quick ? "quick" : "paper",
          r.options.pid == calibration::PidChoice::kPaper ? "the paper's" : "searched"));
  files.data.push_back(dir / "calibration.toml");
}

// A cell whose experiment is not valid says so, never a number.
std::string valid_or(const rig::Validity& v, std::string text) {
  return v.valid ? text : "NOT VALID: " + v.reason;
}

std::string um(double v, double resolution = 0.0) {
  return format_figure(v, "um", resolution);
}

std::string pct(double v) {
  return format_figure(v, "%");
}

// Exactly 0 is the oracle's linearity on whole-micron levels: said to be exact so that it does
// not read as a placeholder (oracle_section explains it).
std::string exact_zero_note(const experiments::LinearityResult& l) {
  return l.metrics.linearity_zero_end_pct == 0.0 ? " (exact by construction)" : "";
}

std::string travel_cell(const ExperimentSet& e) {
  return valid_or(
      e.travel.validity,
      fmt::format("{} @open loop; {} @semi-closed loop", um(e.travel.open_loop_um),
                  um(e.travel.semi_closed_um, experiments::TravelRangeOptions{}.increment_um)));
}

std::string step_cell(const ExperimentSet& e) {
  return valid_or(
      e.step.validity,
      fmt::format("{} @{:g} µm (±2 %); {} to ±10 nm",
                  format_figure(e.step.metrics.settling_time_pct_s, "s"), e.step.desired_um.back(),
                  format_figure(e.step.metrics.settling_time_abs_s, "s")));
}

std::string linearity_cell(const ExperimentSet& e) {
  return valid_or(
      e.linearity.validity,
      fmt::format("{} (zero-end); {} (best fit)", pct(e.linearity.metrics.linearity_zero_end_pct),
                  pct(e.linearity.metrics.linearity_best_fit_pct)) +
          exact_zero_note(e.linearity));
}

std::string repeat_cell(const ExperimentSet& e) {
  const auto one = [](const experiments::RepeatabilityResult& x) {
    return valid_or(x.validity, fmt::format("{} @{:g} µm (n = {})",
                                            format_figure(x.metrics.repeatability_nm, "nm"),
                                            x.target_um, x.metrics.n));
  };
  return one(e.repeat_5um) + "; " + one(e.repeat_10um);
}

// Zero-end / best-fit linearity of one sweep.
std::string sweep_cell(const experiments::LinearityResult& l) {
  return valid_or(l.validity,
                  fmt::format("{} / {}{}", pct(l.metrics.linearity_zero_end_pct),
                              pct(l.metrics.linearity_best_fit_pct), exact_zero_note(l)));
}

std::vector<std::string> sweep_row(const char* name, const experiments::LinearityResult& paper,
                                   const experiments::LinearityResult& oracle) {
  return {name, sweep_cell(paper), sweep_cell(oracle)};
}

std::string margin_text(double value, const char* unit, double at_Hz) {
  return std::isfinite(value) ? fmt::format("{} at {:.0f} Hz", format_figure(value, unit), at_Hz)
                              : std::string("none (no crossover)");
}

void introduction(Document& doc, const ReproductionResult& r, const std::string& config_label) {
  doc.heading(1, "Reproduction of Li et al. (2017) on the piezoshift digital twin");
  doc.paragraph(fmt::format(
      "The paper's calibration and its four experiments (Sections 3 and 4), run on the digital "
      "twin of the paper's hardware through the same controller code that runs on a real bench. "
      "Seed {}, {} schedule, PID gains: {}, configuration: {}. {:.0f} s of simulated time in "
      "{:.1f} s of wall time. First the paper's Table 4 and Figures 10 to 12 beside the paper's "
      "values, then the oracle (the same loop fed the plate's true position), then what goes "
      "beyond the paper, then the calibration.",
      r.options.seed, r.options.quick ? "quick (shortened)" : "the paper's full",
      r.options.pid == calibration::PidChoice::kPaper ? "the paper's (kp 0.6, ki 0.2, kd 0.001)"
                                                      : "the stage-1 search's",
      config_label, r.simulated_time_s, r.wall_time_s));
}

// Table 4 beside the paper's and the commercial stages' rows, each figure against the paper's
// band, and what was not valid.
void table4_section(Document& doc, const ReproductionResult& r,
                    const std::vector<PaperBandRow>& bands) {
  doc.heading(2, "Table 4 and Figures 10 to 12: the paper's results on the twin");
  doc.table({{"", "Travel range", "Step response", "Linearity", "Repeatability (1 σ)"},
             {"This paper", "12.9 µm @open loop; 11.5 µm @semi-closed loop", "<0.3 s @11 µm",
              "0.21 %", "2 nm @5 µm; 3 nm @10 µm"},
             {"Twin, the paper's controller (this run)", travel_cell(r), step_cell(r),
              linearity_cell(r), repeat_cell(r)},
             {"S315.10 (PI)", "12 µm @open loop", "-", "2 % - 4 %", "-"},
             {"NPS-Z-15H (Queensgate)", "15 µm @closed loop", "-", "0.02 %", "-"}});
  std::vector<std::vector<std::string>> rows{
      {"figure", "the paper", "band", "twin (this run)", "against the band"}};
  for (const PaperBandRow& b : bands)
    rows.push_back({b.figure, b.paper, b.band, b.twin, b.verdict()});
  doc.table(std::move(rows));
  doc.paragraph(
      "Bands: the acceptance bands around the paper's values, the ones the project's "
      "tests hold the twin to (reproduction/paper_bands.hpp): the paper's own bound for the step "
      "(settled to ±2 % within 0.3 s), ±0.3 µm and ±0.5 µm around its travels, 0.1 to 0.4 % "
      "around its 0.21 % linearity, and 1 to 3.5 nm and 1.5 to 4.5 nm around its 2 and 3 nm "
      "repeatability (one run each in the paper, given to one significant figure).");
  const std::vector<std::string> invalid = r.invalid_reasons();
  if (invalid.empty()) {
    doc.paragraph(
        "Every experiment of the paper's controller is valid: no supervisor trip, no PID at its "
        "output limit where a value was measured, every target reached and the step settled.");
  } else {
    std::string text =
        "NOT VALID: the following experiments of the paper's controller did not "
        "measure what they claim, so their numbers above are not results:";
    for (const std::string& why : invalid)
      text += "\n- " + why;
    doc.code(text);
  }
}

// "36 ms, within the band (< 0.3 s)", "0.035 %, below the band (0.1 to 0.4 %)".
std::string judged(const PaperBandRow& b) {
  if (!b.valid)
    return b.twin;
  return fmt::format("{}, {} the band ({})", b.twin,
                     b.within ? "within" : (b.below ? "below" : "above"), b.band);
}

// The caption write_figures kept for the figure drawn to file_name.
std::string caption_of(const ReportFiles& files, const std::string& file_name) {
  for (std::size_t i = 0; i < files.figures.size() && i < files.captions.size(); ++i) {
    if (files.figures[i].filename() == file_name)
      return files.captions[i];
  }
  return {};
}

// Figures 10 to 12 in the paper's order, each captioned with the paper's value and its verdict.
void paper_figures_section(Document& doc, const ReproductionResult& r,
                           const std::vector<PaperBandRow>& bands, const ReportFiles& files) {
  const auto caption = [&](const char* file) {
    if (const std::string c = caption_of(files, file); !c.empty())
      doc.paragraph(c);
  };
  doc.heading(3, "Figure 10: step response");
  doc.image(fmt::format("Figure 10: step response to {:g} µm. Paper: settled in < 0.3 s; twin: "
                        "settled to ±2 % in {}",
                        r.step.desired_um.back(), judged(bands[2])),
            "fig10_step_response.png");
  caption("fig10_step_response.png");
  const auto& step = r.step.metrics;
  doc.paragraph(fmt::format(
      "Rise time (10-90 %) {}, overshoot {} at the interferometer's 1 kHz samples and {} on the "
      "true plate between them, step {}; settled to ±10 nm after {}.",
      format_figure(step.rise_time_s, "s"), format_figure(step.overshoot_pct, "%"),
      format_figure(r.step.truth_overshoot_pct, "%"), um(step.step_um, 0.001),
      format_figure(step.settling_time_abs_s, "s")));
  doc.heading(3, "Figure 11: linearity");
  doc.image(fmt::format("Figure 11: linearity, (a) measured − desired with the zero-end line, (b) "
                        "deviation from the "
                        "zero-end and best-fit lines. Paper: 0.21 %; twin: {}",
                        judged(bands[3])),
            "fig11_linearity.png");
  caption("fig11_linearity.png");
  if (bands[3].valid && bands[3].below) {
    const auto& raw = r.linearity_without_cubic;
    const double raw_pct = raw.metrics.linearity_zero_end_pct;
    const bool raw_within = raw.validity.valid && raw_pct >= bands[3].lo && raw_pct <= bands[3].hi;
    doc.paragraph(fmt::format(
        "Below the band, and why: with its cubic the twin's error is its noise and drift; none "
        "of the paper's numbers identifies an error the cubic cannot fit, so the twin does not "
        "invent one (docs/twin.md). Without the cubic the same stage reads {} (zero-end / best "
        "fit){}.",
        sweep_cell(raw), raw_within ? ", within the band by the zero-end line" : ""));
  }
  doc.heading(3, "Figure 12: repeatability");
  doc.image(fmt::format("Figure 12: repeatability, (a) 230 moves to 5 µm, (b) 230 moves to 10 µm. "
                        "Paper: 2 nm and 3 nm (1 σ); twin: {}; {}",
                        judged(bands[4]), judged(bands[5])),
            "fig12_repeatability.png");
  caption("fig12_repeatability.png");
}

// The oracle beside the paper's controller on Table 4's figures.
void oracle_section(Document& doc, const ReproductionResult& r) {
  const ExperimentSet& o = r.oracle;
  doc.heading(2, "The oracle: the same loop fed the plate's true position");
  doc.table({{"Table 4's figure", "twin, the paper's controller",
              "oracle (plate feedback: impossible on hardware)"},
             {"travel range", travel_cell(r), travel_cell(o)},
             {"step response", step_cell(r), step_cell(o)},
             {"linearity (zero-end / best fit)", sweep_cell(r.linearity), sweep_cell(o.linearity)},
             {"repeatability (1 σ)", repeat_cell(r), repeat_cell(o)}});
  doc.paragraph(
      "The oracle is the same loop, the same gains and A, fed the plate's true point "
      "displacements instead of the strain gauges (and so with no cubic to correct): the floor "
      "no controller fed by the gauges can beat.");
  const auto& lin = o.linearity.metrics;
  if (o.linearity.validity.valid && lin.linearity_zero_end_pct == 0.0) {
    doc.paragraph(
        "Its linearity by the paper's protocol is 0 exactly, by construction, not a placeholder: "
        "the oracle holds the plate on its true position at each whole-micron level, and the "
        "interferometer reads that plate to 1 nm, so every reading is its level and both lines "
        "pass through all of them (docs/compare.md). On levels between them, the 0.25 µm grid "
        "and downwards (below), it is not 0; that is where a controller is judged against it.");
  }
  for (const std::string& why : o.invalid_reasons())
    doc.paragraph("Oracle not valid: " + why);
}

void linearity_section(Document& doc, const ReproductionResult& r) {
  doc.heading(3, "Linearity beyond the paper's protocol");
  doc.table(
      {{"sweep (zero-end / best fit)", "paper's controller", "oracle"},
       sweep_row("0 to 11 µm in 1 µm, upwards (the paper's)", r.linearity, r.oracle.linearity),
       sweep_row("0 to 11 µm in 0.25 µm, upwards (levels the calibration never saw)",
                 r.linearity_grid, r.oracle.linearity_grid),
       sweep_row("11 to 1 µm in 1 µm, downwards", r.linearity_down, r.oracle.linearity_down),
       {"the paper's, without the cubic (p = identity)", sweep_cell(r.linearity_without_cubic),
        "-"}});
  doc.paragraph(fmt::format(
      "Without the cubic the semi-closed loop's own nonlinearity (the SGS conditioner's bow and "
      "the ball contact, both outside what the gauges' PID can see) reads {}; the paper measured "
      "0.21 % with its cubic. With the cubic the twin's error is its noise and drift: with those "
      "off, the same sweep reads about 0.002 % (docs/twin.md).",
      sweep_cell(r.linearity_without_cubic)));
}

void phase_step_section(Document& doc, const ReproductionResult& r) {
  doc.heading(3, "Phase step");
  const auto row = [&](const char* name, auto value) {
    return std::vector<std::string>{
        name, valid_or(r.phase_step.validity, value(r.phase_step)),
        valid_or(r.oracle.phase_step.validity, value(r.oracle.phase_step))};
  };
  using PS = experiments::PhaseStepResult;
  doc.table(
      {{"λ/8 step at 5 µm", "paper's controller", "oracle"},
       row("hold jitter, 1 ms exposure means (rms)",
           [](const PS& e) { return format_figure(e.hold_jitter_nm_rms, "nm"); }),
       row("settled to ±1 nm after",
           [](const PS& e) { return format_figure(e.settling_time_s, "s"); }),
       row("final error", [](const PS& e) { return format_figure(e.final_error_nm, "nm"); })});
  doc.paragraph(fmt::format(
      "What a phase-shifting measurement needs: a {:.1f} nm step (π/2 at 632.8 nm) judged on the "
      "plate's true position averaged over each 1 ms camera exposure. The jitter is what the "
      "loop feeds of the gauges' noise into the plate while it holds; the settling time is when "
      "every later exposure stays within ±1 nm of the target, within {:g} ms.",
      r.phase_step.step_nm, 1e3 * r.schedule.phase_step.record_s));
  figure(doc, "Phase step", "phase_step.png", detail::phase_step_figure(r).caption);
}

// Per loop rate and actuator: the identified plant and the calibrated PID's margins on it.
void inner_loop_section(Document& doc, const ReproductionResult& r, bool any_loop) {
  doc.heading(3, "Inner loop: the identified plant and the PID's stability margins");
  std::vector<std::vector<std::string>> rows{{"loop rate", "actuator", "plant gain u -> y",
                                              "model residual (rms)", "gain margin",
                                              "phase margin"}};
  for (const InnerLoopAnalysis& a : r.inner_loop) {
    if (!a.validity.valid) {
      rows.push_back({fmt::format("{:g} kHz", 1e-3 / a.sample_time_s), "-",
                      "not available: " + a.validity.reason, "", "", ""});
      continue;
    }
    for (std::size_t i = 0; i < 3; ++i) {
      const auto& m = a.margins[i];
      const auto& model = a.plant.channel[i];
      rows.push_back({fmt::format("{:g} kHz", 1e-3 / a.sample_time_s), fmt::format("{}", i + 1),
                      fmt::format("{:.3f}", model.dc_gain()),
                      format_figure(1e3 * model.rms_residual_um, "nm"),
                      margin_text(m.gain_margin_dB, "dB", m.phase_crossover_Hz),
                      margin_text(m.phase_margin_deg, "deg", m.gain_crossover_Hz)});
    }
  }
  doc.table(rows);
  doc.paragraph(
      "Each actuator's plant, from the PID's output (µm of command) to its gauge (µm), identified "
      "by least squares (ARX, 3 poles, 4 delayed inputs) from ±80 nm pseudo-random steps around "
      "5 µm, through the loop that ships, so its delays are the real ones; the 10 kHz row runs "
      "the twin's DAQ at 0.1 ms with the same gains re-expressed per sample. The margins are "
      "those of the calibrated PID on that model (runtime/stability_margins.hpp).");
  if (any_loop)
    figure(doc, "Inner loop Bode plot", "inner_loop_bode.png",
           detail::inner_loop_figure(r).caption);
}

// The three calibration stages: PID gains, A and p, each beside the paper's.
void calibration_section(Document& doc, const ReproductionResult& r) {
  const auto& cal = r.calibration;
  const control::SemiClosedLoopParams paper{};
  doc.heading(2, "Calibration");
  doc.heading(3, "Stage 1: PID gains");
  doc.paragraph(
      fmt::format("Each actuator stepped alone (inner loop) to 95 % of what its SGS reads at 10 V "
                  "open loop: {:.3f}, {:.3f}, {:.3f} µm. Scores are the worst of the three "
                  "actuators; a candidate is acceptable with overshoot ≤ 1 %, settled to ±2 % "
                  "within the record and a steady-state error ≤ 5 nm. {} candidates searched.",
                  cal.pid.step_target_um[0], cal.pid.step_target_um[1], cal.pid.step_target_um[2],
                  cal.pid.trials.size()));
  doc.table(
      {{"gains", "kp / ki / kd", "overshoot", "settling (2 %)", "steady-state error", "acceptable"},
       trial_row("paper", cal.pid.paper),
       trial_row("search best", cal.pid.best),
       trial_row("used", cal.pid.paper.gains.kp == cal.controller.gains.kp &&
                                 cal.pid.paper.gains.ki == cal.controller.gains.ki &&
                                 cal.pid.paper.gains.kd == cal.controller.gains.kd
                             ? cal.pid.paper
                             : cal.pid.best)});
  doc.heading(3, "Stage 2: transmission matrix A");
  doc.paragraph(fmt::format(
      "{} poses (each actuator moved alone by {:g} µm from {:g} µm, in closed loop), "
      "least squares: rms residual {}, cond(A) = {:.3f}.",
      cal.matrix.fit.poses, r.schedule.calibration.matrix.move_um,
      r.schedule.calibration.matrix.base_um,
      cal.matrix.fit.poses <= 3 ? std::string("0 (three poses determine A's nine elements exactly)")
                                : format_figure(1e3 * cal.matrix.fit.rms_residual_um, "nm"),
      cal.matrix.fit.condition_number));
  doc.code("identified A:\n" + matrix_text(cal.controller.matrix.a) + "\n\npaper's A:\n" +
           matrix_text(paper.matrix.a));
  doc.heading(3, "Stage 3: cubic polynomial p");
  doc.paragraph(
      fmt::format("{} equally spaced commands over 0 to {:g} µm, {} of them left out with a PID at "
                  "its limit; rms residual {}.",
                  r.schedule.calibration.polynomial.points,
                  r.schedule.calibration.polynomial.max_um, cal.polynomial.saturated_points,
                  format_figure(1e3 * cal.polynomial.fit.rms_residual_um, "nm")));
  doc.code("fitted: " + poly_text(cal.controller.polynomial) +
           "\npaper:  " + poly_text(paper.polynomial));
  doc.paragraph(
      "The paper's A and p describe its own stage; the twin's are identified from the twin by the "
      "same procedure, so they agree where the twin's geometry and sensors follow the paper's and "
      "differ where the paper's stage had effects the twin does not model (docs/twin.md).");
}

void files_section(Document& doc, const ReportFiles& files) {
  doc.heading(2, "Files");
  std::string list;
  for (const auto& f : files.data)
    list += f.filename().string() + "  ";
  doc.paragraph(
      "Data beside this report (CSV columns carry their units; `piezoshift fit` and `piezoshift "
      "analyze` read them): " +
      list);
  doc.paragraph(
      "To watch the stage live: `piezoshift serve --daq sim --http-port 8080`, then open "
      "http://127.0.0.1:8080/ (docs/dashboard.md).");
}

}  // namespace

ReportFiles write_report(const ReproductionResult& r, const fs::path& dir,
                         const std::string& config_label) {
  create_report_folder(dir);
  ReportFiles files;
  write_data(r, dir, files);
  const bool any_loop = detail::write_figures(r, dir, files);
  write_measurement_files(r.measurement, dir, files);

  // The paper's order first, then the oracle, then what goes beyond the paper.
  const std::vector<PaperBandRow> bands = paper_band_rows(r);
  Document doc;
  introduction(doc, r, config_label);
  table4_section(doc, r, bands);
  paper_figures_section(doc, r, bands, files);
  oracle_section(doc, r);
  doc.heading(2, "Beyond the paper");
  doc.paragraph(
      "What the paper does not measure: linearity on levels the calibration never saw and "
      "downwards, the λ/8 phase step a phase-shifting measurement needs, the inner loop's "
      "stability margins, and a measurement through the stage.");
  linearity_section(doc, r);
  phase_step_section(doc, r);
  inner_loop_section(doc, r, any_loop);
  measurement_section(doc, r.measurement);
  calibration_section(doc, r);
  files_section(doc, files);

  files.markdown = dir / "report.md";
  files.html = dir / "report.html";
  write_text(files.markdown, to_markdown(doc.blocks));
  write_text(files.html, to_html(doc.blocks, "piezoshift reproduction"));
  return files;
}

}  // namespace piezoshift::reproduction
