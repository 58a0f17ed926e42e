// `piezoshift reproduce` on the default twin must land where the paper did (Table 4), with the
// paper's controller calibrated on the twin by the paper's procedure. Bands from the issue; where
// the twin cannot reach a band honestly, the test pins what it does reach and says why.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <numbers>

#include <fmt/core.h>

#include "piezoshift/io/plot.hpp"
#include "piezoshift/reproduction/document.hpp"
#include "piezoshift/reproduction/measurement_report.hpp"
#include "piezoshift/reproduction/report.hpp"
#include "piezoshift/reproduction/reproduction.hpp"
#include "piezoshift/reproduction/reproduction_cost.hpp"
#include "piezoshift/reproduction/summary.hpp"
#include "piezoshift/rig/simulation_meter.hpp"

namespace piezoshift::reproduction {
namespace {

// The simulated time the first quick run took, by the simulation meter.
double g_quick_run_simulated_s = 0.0;

const ReproductionResult& quick_run() {
  static const ReproductionResult r = [] {
    ReproduceOptions o;
    o.quick = true;
    o.seed = 1;
    const double before = rig::simulation_meter().simulated_s;
    ReproductionResult result = reproduce(config::ProjectConfig{}, o);
    g_quick_run_simulated_s = rig::simulation_meter().simulated_s - before;
    return result;
  }();
  return r;
}

// The estimate `reproduce --quick` refuses by (reproduction_cost.hpp) is what it costs, within
// 2 % (the static measurements' share of a window varies a little with what they wait for).
TEST(Reproduction, CostEstimateIsWhatTheRunCost) {
  quick_run();
  const double estimate =
      rig::estimate_cost(reproduce_cost(true), config::ProjectConfig{}.twin).simulated_s;
  EXPECT_NEAR(estimate, g_quick_run_simulated_s, 0.02 * g_quick_run_simulated_s);
}

TEST(Reproduction, TravelRangeIsThePapers) {
  const auto& r = quick_run();
  EXPECT_NEAR(r.travel.open_loop_um, 12.9, 0.3);    // Section 4.1: 12.9 um at 150 V
  EXPECT_NEAR(r.travel.semi_closed_um, 11.5, 0.5);  // Section 4.1: 11.5 um
  EXPECT_LT(r.travel.semi_closed_um, r.travel.open_loop_um);
}

TEST(Reproduction, ElevenMicronStepSettlesWithinPointThreeSeconds) {
  const auto& m = quick_run().step.metrics;
  EXPECT_NEAR(m.step_um, 11.0, 0.05);  // the calibrated feedforward reaches the desired 11 um
  EXPECT_LT(m.settling_time_pct_s, 0.3);
  EXPECT_LT(m.overshoot_pct, 2.0);
}

// The paper's band is 0.1 to 0.4 % (its 0.21 %). The twin lands far below it: its only
// deterministic sensor error (the conditioner's 0.1 % bow) is a polynomial, which the cubic of
// stage 3 removes; what is left is noise and drift. The paper's residual needs an error a cubic
// cannot fit (a wave-shaped or history-dependent gauge error), which the paper does not
// characterise, so the twin does not invent it (docs/experiments.md, "What the twin cannot say").
TEST(Reproduction, LinearityAfterCalibrationIsWithinThePapersUpperBound) {
  const auto& lin = quick_run().linearity.metrics;
  EXPECT_EQ(lin.n, 12U);  // 0 to 11 um in 1 um steps
  EXPECT_LT(lin.linearity_zero_end_pct, 0.4);
  EXPECT_LT(lin.linearity_zero_end_pct, 0.05);  // what the twin reaches
  EXPECT_GT(lin.linearity_zero_end_pct, 0.0);
  EXPECT_NEAR(lin.span_um, 11.0, 0.05);
}

// What the cubic is for: the same protocol, same seed, with p = identity. The SGS conditioner's
// 0.1 % bow (Section 3.1) and the ball contact's F^(2/3) compliance leave the semi-closed loop
// 0.29 to 0.33 % off a straight line (full schedule, seeds 1 to 8), inside the paper's band; the
// cubic must take most of it away, or stage 3 did nothing.
TEST(Reproduction, TheCubicRemovesTheSemiClosedLoopsOwnNonlinearity) {
  const auto& r = quick_run();
  ASSERT_TRUE(r.linearity_without_cubic.validity.valid)
      << r.linearity_without_cubic.validity.reason;
  const double raw = r.linearity_without_cubic.metrics.linearity_zero_end_pct;
  EXPECT_GT(raw, 0.1);
  EXPECT_LT(raw, 0.4);
  EXPECT_GT(raw, 3.0 * r.linearity.metrics.linearity_zero_end_pct);
}

// The paper: 2 nm at 5 um, 3 nm at 10 um; issue 11's bands are 1 to 3.5 nm and 1.5 to 4.5 nm.
// The twin's spread comes from the bridge-excitation gain drift and the metrology loop, both
// identified from those two numbers (docs/twin.md); seed 1's quick run reads 2.10 and 2.78 nm,
// and the full schedule over seeds 1 to 8 stays inside both bands (docs/experiments.md).
TEST(Reproduction, RepeatabilityOf230MovesIsNanometres) {
  const auto& r = quick_run();
  EXPECT_EQ(r.repeat_5um.metrics.n, 230U);
  EXPECT_EQ(r.repeat_10um.metrics.n, 230U);
  EXPECT_GE(r.repeat_5um.metrics.repeatability_nm, 1.0);
  EXPECT_LE(r.repeat_5um.metrics.repeatability_nm, 3.5);
  EXPECT_GE(r.repeat_10um.metrics.repeatability_nm, 1.5);
  EXPECT_LE(r.repeat_10um.metrics.repeatability_nm, 4.5);
  EXPECT_NEAR(r.repeat_5um.metrics.mean_um, 5.0, 0.02);
  EXPECT_NEAR(r.repeat_10um.metrics.mean_um, 10.0, 0.02);
}

TEST(Reproduction, IdentifiedMatrixIsThePapersAndCalibrationIsDeterministic) {
  const auto& r = quick_run();
  const control::TransmissionMatrix paper;
  for (std::size_t i = 0; i < 3; ++i) {
    for (std::size_t j = 0; j < 3; ++j) {
      EXPECT_NEAR(r.calibration.controller.matrix.a[i][j], paper.a[i][j], 0.05);
    }
  }
  // the twin's p is near the identity: its sensors are scaled by the identified A
  EXPECT_NEAR(r.calibration.controller.polynomial.p1, 1.0, 0.02);
  ReproduceOptions o;
  o.quick = true;
  o.seed = 1;
  const ReproductionResult again = reproduce(config::ProjectConfig{}, o);
  EXPECT_EQ(again.linearity.measured_um, r.linearity.measured_um);
  EXPECT_EQ(again.repeat_10um.measured_um, r.repeat_10um.measured_um);
  EXPECT_GT(r.simulated_time_s, 1000.0);
}

// Issue 28's done-when: `make demo` shows a measurement. Hariharan's 5 frames of the twin camera
// through `measure`'s library path with the controller seed 1's quick run calibrated.
TEST(Reproduction, ThePhaseShiftingMeasurementRecoversTheSurfaceAndTheSteps) {
  const ReproductionResult& r = quick_run();
  const PhaseMeasurement& m = r.measurement;
  ASSERT_TRUE(m.validity.valid) << m.validity.reason;
  EXPECT_TRUE(r.valid());
  EXPECT_EQ(m.scene.seed, 1U + kMeasurementSeedOffset);  // a session of its own
  ASSERT_EQ(m.sequence.frames.size(), 5U);
  ASSERT_EQ(m.sequence.exposures.size(), 5U);
  // The error is the camera's noise and the stage's: below 1 nm, and not zero (noise-free frames
  // would mean the camera's noise never reached the analysis).
  EXPECT_LT(m.error_rms_nm, 1.0);
  EXPECT_GT(m.error_rms_nm, 0.0);
  EXPECT_GT(m.ideal_error_rms_nm, 0.0);
  EXPECT_LT(m.ideal_error_rms_nm, 1.0);
  // The steps the fringes show, against the plate's true mean piston over each exposure.
  EXPECT_LT(m.analysis.step_error_max_mrad, 20.0);
  ASSERT_EQ(m.analysis.true_steps_rad.size(), 1U);
  for (std::size_t k = 0; k < 5; ++k) {
    EXPECT_NEAR(m.analysis.true_steps_rad[0][k], k * std::numbers::pi / 2.0, 0.2) << k;
    const instrument::ExposureRecord& e = m.sequence.exposures[k];
    EXPECT_GT(e.settled_time_s - e.move_time_s, 0.0) << k;
    EXPECT_LT(e.settled_time_s - e.move_time_s, m.params.on_target.timeout_s) << k;
  }
  // The default test surface: Z4 = 40 nm of the 256 px pupil's surface comes back.
  ASSERT_GE(m.analysis.zernike_nm.size(), 4U);
  EXPECT_NEAR(m.analysis.zernike_nm[3], 40.0, 1.0);
  EXPECT_GT(m.simulated_time_s, 0.2);
  EXPECT_LT(m.simulated_time_s, 1.0);
}

// A measurement that is not valid marks reproduce's validity and its section, never a number.
TEST(Reproduction, AMeasurementThatIsNotValidIsAFailureWithItsReason) {
  ReproductionResult r = quick_run();
  r.measurement.validity.fail("camera twin lost frame 2");
  EXPECT_FALSE(r.valid());
  ASSERT_FALSE(r.invalid_reasons().empty());
  EXPECT_EQ(r.invalid_reasons().back(), "measurement: camera twin lost frame 2");
  const nlohmann::json j = summary_json(r);
  EXPECT_FALSE(j["valid"].get<bool>());
  EXPECT_FALSE(j["measurement_valid"].get<bool>());
  EXPECT_FALSE(j.contains("measurement_error_rms_nm"));
  Document doc;
  measurement_section(doc, r.measurement);
  const std::string md = to_markdown(doc.blocks);
  EXPECT_NE(md.find("NOT VALID: camera twin lost frame 2"), std::string::npos) << md;
  EXPECT_EQ(md.find("measured - true"), std::string::npos) << md;
}

TEST(Reproduction, SummaryHasTheIssuesKeys) {
  const nlohmann::json j = summary_json(quick_run());
  for (const char* key :
       {"travel_open_loop_um", "travel_semi_closed_um", "step_settling_time_s",
        "linearity_zero_end_pct", "repeatability_5um_nm", "repeatability_10um_nm", "identified_A",
        "fitted_p", "simulated_time_s", "wall_time_s", "linearity_without_cubic_zero_end_pct",
        "phase_step_hold_jitter_nm_rms", "phase_step_settling_time_s",
        "oracle_phase_step_hold_jitter_nm_rms", "pid_margins_1kHz_gain_margin_dB",
        "pid_margins_10kHz_phase_margin_deg"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_TRUE(j["valid"].get<bool>());
  EXPECT_TRUE(j["measurement_valid"].get<bool>());
  EXPECT_DOUBLE_EQ(j["measurement_error_rms_nm"].get<double>(),
                   quick_run().measurement.error_rms_nm);
  EXPECT_DOUBLE_EQ(j["measurement_step_error_max_mrad"].get<double>(),
                   quick_run().measurement.analysis.step_error_max_mrad);
  EXPECT_EQ(j["measurement_settle_s"].size(), 5U);
  EXPECT_EQ(j["identified_A"].size(), 3U);
  EXPECT_EQ(j["fitted_p"].size(), 4U);
  EXPECT_DOUBLE_EQ(j["repeatability_5um_nm"].get<double>(),
                   quick_run().repeat_5um.metrics.repeatability_nm);
}

TEST(Reproduction, ReportHasTable4FiguresAndData) {
  if (!io::find_gnuplot())
    GTEST_SKIP() << "gnuplot not installed";
  const auto dir = std::filesystem::temp_directory_path() / "piezoshift_report_test";
  std::filesystem::remove_all(dir);
  const ReportFiles files = write_report(quick_run(), dir, "built-in defaults");
  // Figures 10 to 12, the phase step, the Bode plot, the measurement's surface and Zernike chart
  ASSERT_EQ(files.figures.size(), 7U);
  for (const auto& f : files.figures)
    EXPECT_GT(std::filesystem::file_size(f), 5000U) << f;
  std::ifstream md(files.markdown);
  const std::string text((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("| This paper | 12.9 µm @open loop"), std::string::npos);
  // The paper's order first: Table 4 and Figures 10 to 12 against the paper's bands, then the
  // oracle, then what goes beyond the paper.
  const std::size_t table4 = text.find("## Table 4 and Figures 10 to 12");
  const std::size_t fig12 = text.find("![Figure 12");
  const std::size_t oracle = text.find("## The oracle");
  const std::size_t beyond = text.find("## Beyond the paper");
  ASSERT_NE(table4, std::string::npos);
  EXPECT_LT(table4, text.find("![Figure 10"));
  EXPECT_LT(text.find("![Figure 10"), fig12);
  EXPECT_LT(fig12, oracle);
  EXPECT_LT(oracle, beyond);
  EXPECT_LT(beyond, text.find("![Phase step]"));
  EXPECT_NE(text.find("| Figure 11: linearity (zero-end line) | 0.21 % | 0.1 to 0.4 % |"),
            std::string::npos);
  // seed 1's quick run: 0 % exactly for the oracle on the paper's levels, said to be exact
  EXPECT_NE(text.find("0 % / 0 % (exact by construction)"), std::string::npos);
  EXPECT_NE(text.find("| S315.10 (PI)"), std::string::npos);
  EXPECT_NE(text.find("| NPS-Z-15H (Queensgate)"), std::string::npos);
  EXPECT_NE(text.find("![Figure 10"), std::string::npos);
  EXPECT_NE(text.find("![Phase step](phase_step.png)"), std::string::npos);
  EXPECT_NE(text.find("| hold jitter, 1 ms exposure means (rms) |"), std::string::npos);
  EXPECT_NE(text.find("## A phase-shifting measurement"), std::string::npos);
  EXPECT_NE(text.find("](measurement_surface_nm.png)"), std::string::npos);
  EXPECT_NE(text.find("](measurement_zernike.png)"), std::string::npos);
  EXPECT_NE(text.find(fmt::format("| measured - true surface, RMS | {:.3f} nm |",
                                  quick_run().measurement.error_rms_nm)),
            std::string::npos);
  EXPECT_NE(text.find("`piezoshift measure`"), std::string::npos);
  std::ifstream html_file(dir / "report.html");
  const std::string html((std::istreambuf_iterator<char>(html_file)),
                         std::istreambuf_iterator<char>());
  EXPECT_NE(html.find("<h2>A phase-shifting measurement</h2>"), std::string::npos);
  EXPECT_NE(html.find("src=\"measurement_surface_nm.png\""), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(dir / "measurement_exposures.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir / "report.html"));
  EXPECT_TRUE(std::filesystem::exists(dir / "calibration.toml"));
  EXPECT_TRUE(std::filesystem::exists(dir / "linearity.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir / "phase_step.csv"));
  EXPECT_TRUE(std::filesystem::exists(dir / "linearity_without_cubic.csv"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace piezoshift::reproduction
