// The improved controller identified around the calibration from fringes (the paper's
// three stages and the improved controller's identification, no laser interferometer):
// calibration::calibrate_improved with the static map from instrument::calibrate_from_fringes and
// no dynamic interferometer, against the same identification with the XL-80 (its mode nulled,
// its large moves tried), on the default twin, seed 1.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "piezoshift/calibration/improved_calibration.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/experiments/paper_experiments.hpp"
#include "piezoshift/experiments/phase_step.hpp"
#include "piezoshift/instrument/fringe_calibration.hpp"
#include "twin_bench_camera.hpp"

namespace piezoshift::instrument {
namespace {

TEST(ImprovedFromFringes, ItHoldsAndStepsAsTheXl80sIdentificationDoesBarTheModeItCannotSee) {
  const config::ProjectConfig config;
  const std::uint64_t seed = 1;
  TwinBenchCamera bench(seed);
  control::SemiClosedLoopParams base;
  base.sample_time_s = config.twin.daq.sample_time_s;
  calibration::ImprovedCalibrationOptions io;
  io.paper = calibration::CalibrationOptions::paper_gains_only();
  const calibration::ImprovedCalibrationOutcome xl80 =
      calibration::calibrate_improved(config, base, seed, io);
  io.dynamic_interferometer = false;
  FringeCalibrationOutcome f;
  const calibration::ImprovedCalibrationOutcome fringes = calibration::calibrate_improved(
      config, base, seed, io, [&](const calibration::CalibrationOptions& stages) {
        FringeCalibrationOptions o;
        o.stages = stages;
        f = calibrate_from_fringes(config, base, seed, bench.cam, twin_optics(bench.scene), o);
        if (!f.validity.valid)
          throw rig::ProcedureFailed(f.validity.reason);
        return f.controller;
      });
  // No interferometer: no mode, no trial; A from the fringes within 0.002 of the plant's.
  EXPECT_FALSE(fringes.shaped);
  EXPECT_FALSE(fringes.large_move.tried);
  EXPECT_TRUE(xl80.shaped);
  const control::Mat3& own = config.twin.geometry.transmission_matrix;
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t j = 0; j < 3; ++j)
      EXPECT_NEAR(fringes.controller.matrix.a[i][j], own[i][j], 0.002);
  // The channel models are stage 4's, which reads the gauges alone: the same plant, the same fit
  // to within what A and p change in the commands' meaning.
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_NEAR(fringes.model[i].params.linear_weight, xl80.model[i].params.linear_weight, 0.01);

  const experiments::PhaseStepOptions po;
  const auto step_f = experiments::run_phase_step(config, fringes.controller, seed + 80, po);
  const auto step_x = experiments::run_phase_step(config, xl80.controller, seed + 80, po);
  ASSERT_TRUE(step_f.validity.valid) << step_f.validity.reason;
  ASSERT_TRUE(step_x.validity.valid) << step_x.validity.reason;
  const experiments::StepExperimentOptions so;
  const auto big_f = experiments::run_step_response(config, fringes.controller, seed + 20, so);
  const auto big_x = experiments::run_step_response(config, xl80.controller, seed + 20, so);
  std::printf(
      "lambda/8 step: fringes %.4f s, hold jitter %.3f nm; XL-80 %.4f s, %.3f nm\n"
      "11 um step: fringes %.4f s to 10 nm, true overshoot %.3f %%; XL-80 %.4f s, %.3f %%\n",
      step_f.settling_time_s, step_f.hold_jitter_nm_rms, step_x.settling_time_s,
      step_x.hold_jitter_nm_rms, big_f.metrics.settling_time_abs_s, big_f.truth_overshoot_pct,
      big_x.metrics.settling_time_abs_s, big_x.truth_overshoot_pct);
  // Measured: the hold as the XL-80's identification holds it (0.256 nm both), within the improved
  // controller's 0.3 nm target; the lambda/8 step without the mode nulled 17 ms against 4 ms (the
  // plate rings through the unshaped ramp: what the camera cannot identify costs that step,
  // docs/fizeau.md); the 11 um step 27.8 ms, 0.18 % against 27.2 ms, 0.20 % (its large move is the
  // slew's).
  EXPECT_LE(step_f.hold_jitter_nm_rms, 0.3);
  EXPECT_NEAR(step_f.hold_jitter_nm_rms, step_x.hold_jitter_nm_rms, 0.02);
  EXPECT_LT(step_f.settling_time_s, 0.03);
  EXPECT_GT(step_f.settling_time_s, 2.0 * step_x.settling_time_s);
  ASSERT_TRUE(big_f.validity.valid) << big_f.validity.reason;
  EXPECT_LT(big_f.truth_overshoot_pct, 1.0);
  EXPECT_LT(big_f.metrics.settling_time_abs_s, 1.1 * big_x.metrics.settling_time_abs_s);
}

}  // namespace
}  // namespace piezoshift::instrument
