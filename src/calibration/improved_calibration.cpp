#include "piezoshift/calibration/improved_calibration.hpp"

#include <fmt/format.h>
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "piezoshift/plant/amplifier.hpp"
#include "piezoshift/rig/bench.hpp"
#include "piezoshift/rig/validity.hpp"

namespace piezoshift::calibration {

namespace {

// The excitation: segments (duration, level at the end), linear in between.
struct Segment {
  double duration_s;
  double level_um;
};
// A major loop, reversal curves at decreasing amplitude, steps held for creep, and small steps
// at mid-travel approached from below (what a phase step does). Ramps stay well below the
// amplifier's slew (16 um of command in 1 s).
constexpr Segment kExcitation[] = {
    {0.5, 0.0},
    {1.0, 16.0},
    {1.0, 0.0},
    {0.75, 12.0},
    {0.5, 4.0},
    {0.4, 10.0},
    {0.3, 6.0},
    {0.2, 8.0},
    {0.1, 7.0},
    {0.3, 7.0},
    {0.0, 8.0},
    {3.0, 8.0},
    {0.0, 3.0},
    {3.0, 3.0},
    {0.0, 13.0},
    {3.0, 13.0},
    {0.0, 5.0},
    {2.0, 5.0},
    {0.0, 5.1},
    {0.5, 5.1},
    {0.0, 5.2},
    {0.5, 5.2},
    {0.0, 5.1},
    {0.5, 5.1},
    {0.0, 5.15},
    {0.5, 5.15},
    {0.0, 10.0},
    {3.0, 10.0},
    {0.3, 16.0},
    {2.0, 16.0},
    {0.0, 15.0},
    {1.0, 15.0},
    // Small reversals at three levels: the slope right after a reversal (the linear weight
    // alone), which a phase step after any settling meets.
    {0.5, 3.0},
    {0.5, 3.0},
    {0.05, 3.3},
    {0.2, 3.3},
    {0.05, 3.15},
    {0.2, 3.15},
    {0.05, 3.23},
    {0.2, 3.23},
    {0.05, 3.19},
    {0.2, 3.19},
    {0.3, 8.0},
    {0.5, 8.0},
    {0.05, 8.3},
    {0.2, 8.3},
    {0.05, 8.15},
    {0.2, 8.15},
    {0.05, 8.23},
    {0.2, 8.23},
    {0.05, 8.19},
    {0.2, 8.19},
    {0.05, 8.4},
    {0.2, 8.4},
    {0.3, 6.0},
    {0.5, 6.0},
    {0.05, 5.7},
    {0.2, 5.7},
    {0.05, 5.85},
    {0.2, 5.85},
    {0.05, 5.77},
    {0.2, 5.77},
    {0.05, 5.81},
    {0.2, 5.81},
    {0.05, 5.6},
    {0.2, 5.6},
    {0.5, 0.0},
    {2.0, 0.0},
};

// Stage 7's one trial: the plate's overshoot [%] of a step of step_um on the three points from
// 0, as the interferometer's dynamic samples read it; NaN when the step did not reach its target
// within 1 % (the stroke's end: nothing to judge).
double large_move_overshoot_pct(const config::ProjectConfig& config,
                                const control::SemiClosedLoopParams& controller, std::uint64_t seed,
                                const ImprovedCalibrationOptions& o) {
  rig::Bench bench(config, controller, seed, {rig::Feedback::kGauges, o.paper.limits});
  const auto all = [](double v) { return control::Vec3{v, v, v}; };
  const auto mean3 = [](const control::Vec3& v) { return (v[0] + v[1] + v[2]) / 3.0; };
  bench.drive_points(all(0.0));
  bench.run(o.large_move_pre_s);
  bench.drive_points(all(o.large_move_trial_um));
  std::vector<double> x;
  bench.run(o.large_move_record_s,
            [&](const rig::Bench& b) { x.push_back(mean3(b.twin().interferometer().dynamic_um)); });
  if (bench.faulted())
    throw rig::ProcedureFailed(
        fmt::format("improved calibration, stage 7: the large move tripped the supervisor ({})",
                    runtime::to_string(bench.fault().reason)));
  const std::size_t tail = std::max<std::size_t>(1, x.size() / 10);
  double final_um = 0.0;
  for (std::size_t k = x.size() - tail; k < x.size(); ++k)
    final_um += x[k] / static_cast<double>(tail);
  if (std::fabs(final_um - o.large_move_trial_um) > 0.01 * o.large_move_trial_um)
    return std::numeric_limits<double>::quiet_NaN();
  return 100.0 * (*std::max_element(x.begin(), x.end()) - final_um) / o.large_move_trial_um;
}

// Stage 7 (the header): the slew path kept or turned off on the plant's own large move.
LargeMoveTrial try_large_moves(const config::ProjectConfig& config,
                               control::SemiClosedLoopParams& controller, std::uint64_t seed,
                               const ImprovedCalibrationOptions& o) {
  LargeMoveTrial t;
  if (!(controller.improved.command_slew_um_per_s > 0.0)) {
    t.not_tried = "the slew path is off";
    return t;
  }
  t.slew_um_per_s = controller.improved.command_slew_um_per_s;
  control::SemiClosedLoopParams shaper_only = controller;
  shaper_only.improved.command_slew_um_per_s = 0.0;
  t.slew_overshoot_pct = large_move_overshoot_pct(config, controller, seed, o);
  t.shaper_overshoot_pct = large_move_overshoot_pct(config, shaper_only, seed, o);
  if (!std::isfinite(t.slew_overshoot_pct) || !std::isfinite(t.shaper_overshoot_pct)) {
    t.not_tried = fmt::format("the {} um step did not reach its target (the stroke's end)",
                              o.large_move_trial_um);
    t.slew_kept = true;
    return t;
  }
  t.tried = true;
  t.slew_kept = t.slew_overshoot_pct < o.large_move_keep_below_pct ||
                t.slew_overshoot_pct <= t.shaper_overshoot_pct;
  if (!t.slew_kept)
    controller = shaper_only;
  return t;
}

}  // namespace

double improved_excitation_duration_s() {
  double t = 0.0;
  for (const Segment& s : kExcitation)
    t += s.duration_s;
  return t;
}

double improved_excitation_um(double t_s) {
  double t0 = 0.0;
  double level = 0.0;
  for (const Segment& s : kExcitation) {
    if (s.duration_s == 0.0) {
      if (t_s >= t0)
        level = s.level_um;
      continue;
    }
    if (t_s < t0 + s.duration_s)
      return level + (s.level_um - level) * (t_s - t0) / s.duration_s;
    t0 += s.duration_s;
    level = s.level_um;
  }
  return level;
}

ImprovedCalibrationOutcome calibrate_improved(const config::ProjectConfig& config,
                                              const control::SemiClosedLoopParams& base,
                                              std::uint64_t seed,
                                              const ImprovedCalibrationOptions& options,
                                              const rig::Progress& progress) {
  CalibrationOutcome xl80;
  ImprovedCalibrationOutcome out =
      calibrate_improved(config, base, seed, options, [&](const CalibrationOptions& static_map) {
        xl80 = calibrate(config, base, seed, static_map, progress);
        return xl80.controller;
      });
  out.static_map = std::move(xl80);
  return out;
}

namespace {

// Stage 4: the channel models from an open-loop excitation (the header).
void identify_channel_models(const config::ProjectConfig& config,
                             const control::SemiClosedLoopParams& paper, std::uint64_t seed,
                             const ImprovedCalibrationOptions& options,
                             ImprovedCalibrationOutcome& out) {
  rig::Bench bench(config, paper, seed, {rig::Feedback::kGauges, options.paper.limits});
  const double T = bench.sample_time_s();
  const auto ticks = static_cast<std::size_t>(std::llround(improved_excitation_duration_s() / T));
  for (std::size_t k = 0; k < ticks; ++k) {
    const double u = std::clamp(improved_excitation_um(static_cast<double>(k) * T),
                                paper.output_min_um, paper.output_max_um);
    control::Vec3 volts{};
    for (std::size_t i = 0; i < 3; ++i)
      volts[i] = paper.scaling[i].um_to_dac(u);
    bench.drive_open_loop(volts);
    bench.run(T);
    const runtime::CycleSample& s = bench.last_cycle();
    out.record_t_s.push_back(static_cast<double>(k) * T);
    for (std::size_t i = 0; i < 3; ++i) {
      out.record_command_um[i].push_back(u);
      out.record_gauge_um[i].push_back(paper.scaling[i].sgs_to_um(s.ai_V[i]));
    }
  }
  if (bench.faulted())
    throw rig::ProcedureFailed(
        fmt::format("improved calibration: the excitation tripped the supervisor ({})",
                    runtime::to_string(bench.fault().reason)));
  for (std::size_t i = 0; i < 3; ++i)
    out.model[i] =
        fit_hysteresis_creep(out.record_command_um[i], out.record_gauge_um[i], T, options.model);
}

// Stage 5: the plate's mode, from the interferometer's dynamic samples after a small open-loop
// step (the gauges' conditioner filters it out; the plate rings). Prony's method on the
// samples: x_k = a1 x_{k-1} + a2 x_{k-2} + c, a damped cosine's recursion, gives cos(theta)
// = a1 / (2 sqrt(-a2)) at the interferometer's rate, folded like any sampled mode.
PlateModeEstimate ring_down_mode(const config::ProjectConfig& config,
                                 const control::SemiClosedLoopParams& paper, std::uint64_t seed,
                                 const ImprovedCalibrationOptions& options,
                                 std::vector<double>& record_t_s, std::vector<double>& record_um) {
  rig::Bench bench(config, paper, seed, {rig::Feedback::kGauges, options.paper.limits});
  const auto volts = [&](double u) {
    control::Vec3 v{};
    for (std::size_t i = 0; i < 3; ++i)
      v[i] = paper.scaling[i].um_to_dac(u);
    return v;
  };
  bench.drive_open_loop(volts(options.mode_step_from_um));
  bench.run(1.0);
  bench.drive_open_loop(volts(options.mode_step_from_um + options.mode_step_um));
  double last_t = -1.0;
  const double step_t = bench.time_s();
  bench.run(options.mode_record_s, [&](const rig::Bench& b) {
    const plant::InterferometerReading& r = b.twin().interferometer();
    if (r.dynamic_time_s != last_t) {
      last_t = r.dynamic_time_s;
      record_t_s.push_back(r.dynamic_time_s - step_t);
      record_um.push_back((r.dynamic_um[0] + r.dynamic_um[1] + r.dynamic_um[2]) / 3.0);
    }
  });
  return identify_plate_mode(record_um, config.twin.interferometer.dynamic_sample_rate_Hz);
}

// The plate's modes lie far above this (1024 to 1700 Hz over docs/twin.md's plates); below it
// the record's 30 ms cannot resolve a peak.
constexpr double kVerdictLowestMode_Hz = 200.0;

// Stages 5 and 5b: the mode as the loop's interferometer samples it (the shaper's), then
// unfolded for the verdict on the loop's rate. 5b runs on a bench of its own, so every other
// stage and the controller are what they were without it.
void identify_mode(const config::ProjectConfig& config, const control::SemiClosedLoopParams& paper,
                   std::uint64_t seed, const ImprovedCalibrationOptions& options,
                   ImprovedCalibrationOutcome& out) {
  out.mode =
      ring_down_mode(config, paper, seed + 5, options, out.mode_record_t_s, out.mode_record_um);
  out.unfolded_mode = out.mode;
  if (config.twin.interferometer.dynamic_sample_rate_Hz < options.verdict_interferometer_rate_Hz) {
    // The step made at the interferometer's rate too (the DAQ with it): one clean edge, so the
    // ring is the plate's, not the 1 kHz staircase's.
    config::ProjectConfig fast = config;
    fast.twin.interferometer.dynamic_sample_rate_Hz = options.verdict_interferometer_rate_Hz;
    fast.twin.daq.sample_time_s = 1.0 / options.verdict_interferometer_rate_Hz;
    control::SemiClosedLoopParams open = paper;
    open.sample_time_s = fast.twin.daq.sample_time_s;
    std::vector<double> t, x;
    try {
      out.unfolded_mode = ring_down_mode(fast, open, seed + 8, options, t, x);
    } catch (const std::invalid_argument&) {  // a twin that cannot run at that rate: no verdict
      out.unfolded_mode = PlateModeEstimate{};
      return;
    }
    // The loudest peak of the ring (1 Hz steps) rather than Prony's one-mode fit, which the
    // tilts blend in: 1020, 1170, 1188, 1415 Hz against the twin's 1024, 1175, 1190 and 1419
    // (thick-plate, payload, contact-spread, default; Prony 1011, 1159, 1181, 1398).
    const double peak_Hz =
        ring_peak_Hz(x, options.verdict_interferometer_rate_Hz, kVerdictLowestMode_Hz);
    if (peak_Hz > 0.0)
      out.unfolded_mode.mode_Hz = peak_Hz;
  }
  out.rate_verdict = judge_loop_rate(out.unfolded_mode.mode_Hz, 1.0 / paper.sample_time_s,
                                     out.model[0].delay_ticks, options.verdict_phase_step_target_s);
}

}  // namespace

ImprovedCalibrationOutcome calibrate_improved(const config::ProjectConfig& config,
                                              const control::SemiClosedLoopParams& base,
                                              std::uint64_t seed,
                                              const ImprovedCalibrationOptions& options,
                                              const StaticMapStages& static_map) {
  ImprovedCalibrationOutcome out;
  // Stage 0: the gains the static map's stages hold with, chosen before they excite the plant.
  out.holding = holding_gains(config, base, seed + 6, options.holding,
                              "improved calibration, stage 0 (the inner loop)");
  CalibrationOptions stages = options.paper;
  if (out.holding.scale < 1.0)
    stages.holding_gains = out.holding.gains;
  const control::SemiClosedLoopParams paper = static_map(stages);
  identify_channel_models(config, paper, seed + 4, options, out);
  if (options.dynamic_interferometer)
    identify_mode(config, paper, seed, options, out);
  const ImprovedDesign design =
      design_improved_controller(config, paper, out.model, out.mode, options);
  out.controller = design.controller;
  out.shaped = design.shaped;
  if (options.dynamic_interferometer)
    out.large_move = try_large_moves(config, out.controller, seed + 7, options);
  else
    out.large_move.not_tried = "no laser interferometer: a camera cannot sample the plate's mode";
  return out;
}

ImprovedDesign design_improved_controller(const config::ProjectConfig& config,
                                          const control::SemiClosedLoopParams& paper,
                                          const std::array<HysteresisFit, 3>& model,
                                          const PlateModeEstimate& mode,
                                          const ImprovedCalibrationOptions& options) {
  ImprovedDesign out;
  control::SemiClosedLoopParams c = paper;
  c.kind = control::ControllerKind::kImproved;
  double min_slope = 1e9;
  for (std::size_t i = 0; i < 3; ++i) {
    c.improved.model[i] = model[i].params;
    min_slope = std::min(min_slope, model[i].params.linear_weight);
  }
  c.improved.sample_time_s = c.sample_time_s;
  c.improved.reference_delay_ticks = model[0].delay_ticks;
  const double slew_V_per_s = plant::amplifier_slew_rate_V_per_s(
      config.twin.amplifier, config.design.actuator.capacitance_F);
  const double rate_command_um_per_s =
      slew_V_per_s / config.twin.amplifier.gain / paper.scaling[0].drive_V_per_um;
  // The mode as folded at the interferometer's rate is what the shaper needs when the loop runs at
  // that rate; at another rate the fold is ambiguous unless the interferometer saw the mode below
  // its Nyquist frequency.
  const double loop_rate_Hz = 1.0 / c.sample_time_s;
  const bool same_rate = std::fabs(loop_rate_Hz - mode.sample_rate_Hz) < 1e-6 * loop_rate_Hz;
  const bool unfolded = mode.mode_Hz > 0.0 && mode.mode_Hz < 0.45 * mode.sample_rate_Hz &&
                        mode.sample_rate_Hz >= loop_rate_Hz;
  out.shaped = mode.mode_Hz > 0.0 && (same_rate || unfolded);
  c.improved.shaper =
      control::design_mode_shaper(out.shaped ? mode.mode_Hz : 0.0, c.sample_time_s,
                                  options.slew_margin * rate_command_um_per_s * min_slope);
  // Large moves at the slew the supervisor passes (it clamps each DAQ step to max_slew T), in
  // command um: the amplifier's own current limit is above it (25.9 against 22.5 V/ms).
  const double passed_V_per_s =
      std::min(options.paper.limits.max_slew_V_per_s, slew_V_per_s / config.twin.amplifier.gain);
  c.improved.command_slew_um_per_s =
      options.large_move_slew_fraction * passed_V_per_s / paper.scaling[0].drive_V_per_um;
  c.improved.slew_approach_um = options.large_move_approach_um;
  c.improved.correction_ki =
      2.0 * std::numbers::pi * options.correction_bandwidth_Hz * c.sample_time_s;
  c.improved.correction_ki_max =
      2.0 * std::numbers::pi * options.boost_bandwidth_Hz * c.sample_time_s;
  out.controller = c;
  return out;
}

}  // namespace piezoshift::calibration
