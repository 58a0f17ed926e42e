// The improved controller (docs/control.md), calibrated by its own procedure on the twin and judged
// through the shipping loop beside the paper's controller calibrated on the same plant: the
// lambda/8 phase step (1 ms exposures of the true plate) and the 11 um step. Figures in
// docs/control.md; the targets not met are listed there.
#include <gtest/gtest.h>

#include "piezoshift/calibration/calibration_file.hpp"
#include "piezoshift/calibration/holding_gains.hpp"
#include "piezoshift/calibration/improved_calibration.hpp"
#include "piezoshift/calibration/loop_identification.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/experiments/paper_experiments.hpp"
#include "piezoshift/experiments/phase_step.hpp"
#include "piezoshift/io/config_file.hpp"
#include "piezoshift/rig/bench.hpp"
#include "piezoshift/runtime/control_cycle.hpp"
#include "test_paths.hpp"

namespace piezoshift::calibration {
namespace {

ImprovedCalibrationOutcome calibrated(const config::ProjectConfig& config, std::uint64_t seed) {
  ImprovedCalibrationOptions o;
  o.paper = CalibrationOptions::paper_gains_only();
  control::SemiClosedLoopParams base;
  base.sample_time_s = config.twin.daq.sample_time_s;
  return calibrate_improved(config, base, seed, o);
}

struct PhaseSteps {
  experiments::PhaseStepResult paper, improved;
};

PhaseSteps phase_steps(const config::ProjectConfig& config, const ImprovedCalibrationOutcome& c,
                       std::uint64_t seed) {
  const experiments::PhaseStepOptions o;
  return {experiments::run_phase_step(config, c.static_map.controller, seed + 80, o),
          experiments::run_phase_step(config, c.controller, seed + 80, o)};
}

// Default twin, seed 1. Measured (compare's seed 1): hold jitter 0.26 nm against the paper's
// 0.53; settling to +-1 nm in 4 ms against 80 ms; the 11 um step within 2 % in 13 ms against 36.
TEST(ImprovedController, OnTheDefaultTwinItHoldsQuieterAndSettlesFaster) {
  const config::ProjectConfig config;
  const ImprovedCalibrationOutcome c = calibrated(config, 1);
  EXPECT_TRUE(c.shaped);
  // The piston mode, 1419 Hz, folds to 419 Hz at the interferometer's 1 kHz.
  EXPECT_NEAR(c.mode.mode_Hz, 419.0, 25.0);
  // Stage 5b sees it unfolded (1415 Hz measured), and it is no limit at 1 kHz: no verdict.
  EXPECT_NEAR(c.rate_verdict.mode_Hz, 1419.0, 10.0);
  EXPECT_FALSE(c.rate_verdict.mode_is_the_limit);
  for (const HysteresisFit& m : c.model) {
    EXPECT_EQ(m.delay_ticks, 2U);
    EXPECT_LT(m.rms_residual_um, 0.012);
  }
  const PhaseSteps p = phase_steps(config, c, 1);
  ASSERT_TRUE(p.improved.validity.valid) << p.improved.validity.reason;
  EXPECT_LE(p.improved.hold_jitter_nm_rms, 0.3);  // the improved controller's target
  EXPECT_LT(p.improved.hold_jitter_nm_rms, 0.6 * p.paper.hold_jitter_nm_rms);
  EXPECT_LT(p.improved.settling_time_s, 0.6 * p.paper.settling_time_s);

  // The correction loop's margins on the identified loop (its real delays), at the hold's gain
  // and at the boost's ceiling: the design asks for 6 dB and 45 deg.
  const LoopIdentification loop = identify_loop(config, c.static_map.controller, 91);
  for (const double ki :
       {c.controller.improved.correction_ki, c.controller.improved.correction_ki_max}) {
    for (const runtime::StabilityMargins& m : correction_margins(loop, c.controller.improved, ki)) {
      EXPECT_GE(m.gain_margin_dB, 6.0) << ki;
      EXPECT_GE(m.phase_margin_deg, 45.0) << ki;
    }
  }

  const experiments::StepExperimentOptions so;
  const auto paper = experiments::run_step_response(config, c.static_map.controller, 21, so);
  const auto improved = experiments::run_step_response(config, c.controller, 21, so);
  ASSERT_TRUE(improved.validity.valid) << improved.validity.reason;
  EXPECT_LT(improved.metrics.settling_time_pct_s, 0.5 * paper.metrics.settling_time_pct_s);
}

// The same procedure on plants other than the default (within docs/twin.md's ranges): a stiffer
// hysteresis with twice the gauge creep; a 0.5 kg payload (the plate's modes move down) on a
// smaller ball; other stroke spreads with faster creep. On each the calibration finds its own
// models and mode, and the hold is quieter than the paper's controller's on that plant.
TEST(ImprovedController, TheSameProcedureWorksOnOtherPlants) {
  config::ProjectConfig a;
  a.twin.piezo.hysteresis.hysteresis_fraction = 0.15;
  a.twin.sgs.gauge_creep_fraction = 0.0004;
  config::ProjectConfig b;
  b.twin.plate.payload_mass_kg = 0.5;
  b.twin.contact.ball_radius_m = 0.004;
  config::ProjectConfig d;
  d.twin.piezo.free_stroke_scale = {1.05, 0.95, 1.0};
  d.twin.piezo.creep.per_decade_fraction = 0.02;
  double default_mode_Hz = 0.0;
  int k = 0;
  for (const config::ProjectConfig* config : {&a, &b, &d}) {
    SCOPED_TRACE(k++);
    const ImprovedCalibrationOutcome c = calibrated(*config, 3);
    if (config == &a) {
      default_mode_Hz = c.mode.mode_Hz;
    } else if (config == &b) {
      // A heavier plate: a lower mode (above 1 kHz), which folds to a lower alias at 1 kHz.
      EXPECT_LT(c.mode.mode_Hz, default_mode_Hz - 100.0);
    }
    const PhaseSteps p = phase_steps(*config, c, 3);
    ASSERT_TRUE(p.improved.validity.valid) << p.improved.validity.reason;
    EXPECT_LE(p.improved.hold_jitter_nm_rms, 0.35);
    EXPECT_LT(p.improved.hold_jitter_nm_rms, 0.7 * p.paper.hold_jitter_nm_rms);
  }
}

// configs/plants/ at compare's 10 kHz (the DAQ at 0.1 ms, the interferometer's dynamic
// samples at 10 kHz).
config::ProjectConfig plant_at_10kHz(const std::string& name) {
  config::ProjectConfig c =
      config::load_project_config(testing::source_dir() + "/configs/plants/" + name + ".toml");
  c.twin.daq.sample_time_s = 1e-4;
  c.twin.interferometer.dynamic_sample_rate_Hz = 1e4;
  return c;
}

// The diagnosis: the paper's gains re-expressed at 10 kHz ring up at a 20 mm plate's mode (the
// calibration's stage 2 then tripped the supervisor); on the default plate the ring decays.
TEST(ImprovedController, ThePapersGainsAt10kHzRingUpOnAThickerPlate) {
  control::SemiClosedLoopParams paper;
  paper.sample_time_s = 1e-4;
  const RingTest thick = ring_test(plant_at_10kHz("thick-plate"), paper, 7);
  EXPECT_FALSE(thick.holds);
  EXPECT_TRUE(thick.aborted || thick.late_ring_um > thick.early_ring_um)
      << thick.early_ring_um << " " << thick.late_ring_um;
  // The ring is the plate's lowest mode (1024 Hz on this plate), as the loop sees it at 10 kHz.
  EXPECT_NEAR(thick.ring_Hz, 1100.0, 150.0);
  config::ProjectConfig fast;
  fast.twin.daq.sample_time_s = 1e-4;
  fast.twin.interferometer.dynamic_sample_rate_Hz = 1e4;
  // Stable, its ring decaying (0.016 -> 0.012 um over 30 ms), if not by the 0.7 a margin needs.
  const RingTest nominal = ring_test(fast, paper, 7);
  EXPECT_FALSE(nominal.aborted);
  EXPECT_LT(nominal.late_ring_um, 0.9 * nominal.early_ring_um) << nominal.early_ring_um;
}

// The fix: the improved calibration at 10 kHz chooses its holding gains on the plant first
// (stage 0) and completes on the plants where it tripped the supervisor; its 10 kHz lambda/8 step
// is then valid. At 1 kHz on the default twin stage 0 keeps the paper's gains (one test).
TEST(ImprovedController, At10kHzStageZeroHoldsThickerAndHeavierPlates) {
  for (const char* name : {"thick-plate", "payload"}) {
    SCOPED_TRACE(name);
    const config::ProjectConfig config = plant_at_10kHz(name);
    const ImprovedCalibrationOutcome c = calibrated(config, 1);
    EXPECT_LT(c.holding.scale, 0.75);  // the paper's gains, tested at 2 x, did not hold
    EXPECT_GE(c.holding.scale, 0.05);
    EXPECT_TRUE(c.holding.test.holds);
    const experiments::PhaseStepResult p =
        experiments::run_phase_step(config, c.controller, 86, experiments::PhaseStepOptions{});
    ASSERT_TRUE(p.validity.valid) << p.validity.reason;
    EXPECT_LE(p.hold_jitter_nm_rms, 0.35);
  }
  const ImprovedCalibrationOutcome nominal = calibrated(config::ProjectConfig{}, 1);
  EXPECT_EQ(nominal.holding.scale, 1.0);
  EXPECT_EQ(nominal.holding.tests, 1);
}

// What limits the improved lambda/8 step at 1 kHz on configs/plants/thick-plate.toml
// (docs/compare.md): the 20 mm plate's piston mode, 1024 Hz, sits 2.4 % above the 1 kHz tick,
// so each command step rings it by about the step on the true plate, at an alias of 24 Hz that
// stage 5 does not resolve in its 30 ms record and that a positive tick-synchronous shaper could
// only null over pi / theta = 21 ticks. The 1 ms exposures average the ring itself out (to 2.3 %),
// but while it decays (7.7 ms) the plate's mean sits a few nm off, and the step takes 30 to 37 ms
// to stay within +-1 nm (seeds 1 to 3). The same plant with the modes' damping at 0.1 settles in
// 4 ms with the same procedure: the mode, not the channel models, sets it.
TEST(ImprovedController, At1kHzAThickPlatesModeNearTheTickRateSetsThePhaseStep) {
  config::ProjectConfig thick =
      config::load_project_config(testing::source_dir() + "/configs/plants/thick-plate.toml");
  const ImprovedCalibrationOutcome c = calibrated(thick, 1);
  EXPECT_FALSE(c.shaped);
  // The calibration says so: stage 5b's mode (1020 Hz measured; the twin's 1024), the 1 kHz step
  // it allows (27 ms) and a faster rate that meets 5 ms.
  EXPECT_TRUE(c.rate_verdict.mode_is_the_limit) << c.rate_verdict.mode_Hz;
  EXPECT_NEAR(c.rate_verdict.mode_Hz, 1024.0, 10.0);
  EXPECT_GT(c.rate_verdict.step_s, 20e-3);
  EXPECT_GT(c.rate_verdict.faster_rate_Hz, 1000.0);
  EXPECT_LE(c.rate_verdict.faster_step_s, 5e-3);
  // The true plate after the step (the controller's own bench, seed 81): its ring over one tick.
  rig::Bench bench(thick, c.controller, 81);
  bench.drive_points(control::Vec3{5.0, 5.0, 5.0});
  bench.run(1.5);
  bench.drive_points(control::Vec3{5.0791, 5.0791, 5.0791});
  double ring_nm = 0.0;
  bench.run(0.005, [&](const rig::Bench& b) {
    const plant::TwinTruth& t = b.twin().truth();
    ring_nm =
        std::max(ring_nm, 1e3 * (t.period_max_mean_points_um - t.period_min_mean_points_um) / 2);
  });
  EXPECT_GT(ring_nm, 50.0);  // measured 73 nm: nearly the 79 nm step
  const experiments::PhaseStepOptions o;
  const experiments::PhaseStepResult p = experiments::run_phase_step(thick, c.controller, 81, o);
  ASSERT_TRUE(p.validity.valid) << p.validity.reason;
  EXPECT_GT(p.settling_time_s, 20e-3);  // measured 37 ms (compare --quick --seeds 1-3: 35 ms)

  thick.twin.mechanics.modal_damping_ratio = 0.1;
  const ImprovedCalibrationOutcome damped = calibrated(thick, 1);
  const experiments::PhaseStepResult q =
      experiments::run_phase_step(thick, damped.controller, 81, o);
  ASSERT_TRUE(q.validity.valid) << q.validity.reason;
  EXPECT_LE(q.settling_time_s, 5e-3);  // measured 4 ms
}

// The 11 um step on configs/plants/payload.toml (docs/compare.md, "Large steps"): made
// by the shaper's rate limit, the 1 kHz DAQ steps (about 12 V at the stack) are each slewed by
// the current-limited amplifier in half a tick and then held, which rings the 1170 Hz piston mode
// every tick, and the shaped ramp's unequal steps do not cancel it: the plate overshoots by 3 %.
// Made at the slew the supervisor passes, the amplifier slews through the ticks and the shaper
// makes the last 1 um: 0.3 %.
TEST(ImprovedController, LargeStepAtTheSlewLimitDoesNotRingThePlate) {
  const config::ProjectConfig payload =
      config::load_project_config(testing::source_dir() + "/configs/plants/payload.toml");
  const ImprovedCalibrationOutcome c = calibrated(payload, 1);
  EXPECT_GT(c.controller.improved.command_slew_um_per_s, 2000.0);  // 0.98 x 1.5 V/ms / 0.625
  const experiments::StepExperimentOptions o;                      // 11 um, as compare
  const experiments::StepExperimentResult s =
      experiments::run_step_response(payload, c.controller, 21, o);
  ASSERT_TRUE(s.validity.valid) << s.validity.reason;
  EXPECT_LT(s.truth_overshoot_pct, 1.0);  // measured 0.28 %

  control::SemiClosedLoopParams shaped_only = c.controller;
  shaped_only.improved.command_slew_um_per_s = 0.0;
  const experiments::StepExperimentResult r =
      experiments::run_step_response(payload, shaped_only, 21, o);
  ASSERT_TRUE(r.validity.valid) << r.validity.reason;
  EXPECT_GT(r.truth_overshoot_pct, 2.0);  // measured 3.1 %
  // Stage 7 tried both on the plant: 0.06 % read with the slew path, 2.34 % without; kept.
  EXPECT_TRUE(c.large_move.tried);
  EXPECT_TRUE(c.large_move.slew_kept);
  EXPECT_LT(c.large_move.slew_overshoot_pct, c.large_move.shaper_overshoot_pct);
}

// The what-if equal legs (configs/what-if/equal-legs.toml): there the slew's stop left
// a ring of 1.42 % of the 11 um step (seed 1), the shaper alone 0.20 %. Stage 7 reads the two on
// the plant with the interferometer's 1 kHz samples (0.88 against 0.22 %), so the slew path is
// turned off and the step is the shaper's: under 1 % of true overshoot.
TEST(ImprovedController, TheLargeMoveTrialTurnsTheSlewOffWhereItsStopRingsThePlate) {
  const config::ProjectConfig legs =
      config::load_project_config(testing::source_dir() + "/configs/what-if/equal-legs.toml");
  const ImprovedCalibrationOutcome c = calibrated(legs, 1);
  ASSERT_TRUE(c.large_move.tried) << c.large_move.not_tried;
  EXPECT_FALSE(c.large_move.slew_kept);
  EXPECT_GT(c.large_move.slew_overshoot_pct, 0.5);  // measured 0.88 %
  EXPECT_LT(c.large_move.shaper_overshoot_pct, c.large_move.slew_overshoot_pct);
  EXPECT_EQ(c.controller.improved.command_slew_um_per_s, 0.0);
  const experiments::StepExperimentResult s =
      experiments::run_step_response(legs, c.controller, 21, experiments::StepExperimentOptions{});
  ASSERT_TRUE(s.validity.valid) << s.validity.reason;
  EXPECT_LT(s.truth_overshoot_pct, 1.0);  // measured 0.20 %
  control::SemiClosedLoopParams slewed = c.controller;
  slewed.improved.command_slew_um_per_s = c.large_move.slew_um_per_s;  // as stage 6 designed it
  const experiments::StepExperimentResult r =
      experiments::run_step_response(legs, slewed, 21, experiments::StepExperimentOptions{});
  ASSERT_TRUE(r.validity.valid) << r.validity.reason;
  EXPECT_GT(r.truth_overshoot_pct, 1.0);  // measured 1.42 %
}

TEST(ImprovedController, CalibrationFileRoundTripsAndRefusesAnotherRate) {
  const ImprovedCalibrationOutcome c = calibrated(config::ProjectConfig{}, 2);
  const std::string text = format_calibration(c.controller, "test");
  const io::ConfigFile file = io::ConfigFile::parse(text, "cal.toml");
  control::SemiClosedLoopParams back;
  read_controller_section(file, back);
  ASSERT_EQ(back.kind, control::ControllerKind::kImproved);
  const control::ImprovedParams& x = c.controller.improved;
  const control::ImprovedParams& y = back.improved;
  EXPECT_EQ(y.shaper.taps, x.shaper.taps);
  EXPECT_EQ(y.shaper.weight, x.shaper.weight);
  EXPECT_EQ(y.correction_ki, x.correction_ki);
  EXPECT_EQ(y.reference_delay_ticks, x.reference_delay_ticks);
  EXPECT_EQ(y.command_slew_um_per_s, x.command_slew_um_per_s);
  EXPECT_EQ(y.slew_approach_um, x.slew_approach_um);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(y.model[i].weight, x.model[i].weight);
    EXPECT_EQ(y.model[i].creep_gain, x.model[i].creep_gain);
    EXPECT_EQ(y.model[i].creep_terms, x.model[i].creep_terms);
  }
  back.sample_time_s = 1e-4;  // a loop at 10 kHz cannot run taps designed at 1 kHz
  EXPECT_THROW(runtime::ControlCycle(back, runtime::SafetyLimits{}), std::invalid_argument);
  // A tap list that does not sum to 1 is refused, naming the key.
  std::string bad = text;
  bad.replace(bad.find("shaper_taps = ["), 15, "shaper_taps = [0.5, ");
  try {
    const io::ConfigFile f = io::ConfigFile::parse(bad, "bad.toml");
    read_controller_section(f, back);
    FAIL() << "accepted";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("shaper_taps"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace piezoshift::calibration
