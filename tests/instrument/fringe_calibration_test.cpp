// The paper's calibration with the Fizeau's fringes as the interferometer
// (fringe_calibration.hpp), through the shipping loop on the simulated bench with the twin camera,
// against the plant's own A and against the XL-80's calibration (calibration::calibrate) on the
// same seed: the acceptance figures of the calibration from fringes, on three plants.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include "piezoshift/calibration/calibration_procedure.hpp"
#include "piezoshift/camera/camera_config.hpp"
#include "piezoshift/camera/twin_camera.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/instrument/fringe_calibration.hpp"
#include "piezoshift/reproduction/paper_bands.hpp"
#include "piezoshift/reproduction/reproduction.hpp"
#include "scripted_camera.hpp"
#include "twin_bench_camera.hpp"

namespace piezoshift::instrument {
namespace {

double worst(const control::Mat3& a, const control::Mat3& b) {
  double w = 0.0;
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t j = 0; j < 3; ++j)
      w = std::max(w, std::fabs(a[i][j] - b[i][j]));
  return w;
}

// Stage 1 with the paper's gains alone (it reads no interferometer: the same in both paths).
FringeCalibrationOptions paper_gains() {
  FringeCalibrationOptions o;
  o.stages = calibration::CalibrationOptions::paper_gains_only();
  return o;
}

struct Plant {
  std::string name;
  config::ProjectConfig config;
};

// The done-when's three plants: the default twin; the gauges' gains a few per cent apart (A's
// rows scaled: A = G W^-1, geometry.hpp, so g scales and the points stay); unequal legs (the
// stacks' strokes of configs/plants/thick-plate.toml, 1.05 / 0.95 / 1.0: A unchanged, the
// volts a move takes are not).
Plant plant(int k) {
  Plant p{"default twin", {}};
  if (k == 1) {
    p.name = "gauge gains 1.03 / 0.97 / 1.00";
    const std::array<double, 3> scale{1.03, 0.97, 1.0};
    for (std::size_t i = 0; i < 3; ++i)
      for (double& v : p.config.twin.geometry.transmission_matrix[i])
        v *= scale[i];
  } else if (k == 2) {
    p.name = "unequal legs 1.05 / 0.95 / 1.00";
    p.config.twin.piezo.free_stroke_scale = {1.05, 0.95, 1.0};
  }
  return p;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct Table4Figures {
  std::array<double, 4> v{};  // step settling [s], linearity [%], repeatability 5 / 10 um [nm]
  bool valid = true;
};

Table4Figures table4(const reproduction::ExperimentSet& e) {
  return {{e.step.metrics.settling_time_pct_s, e.linearity.metrics.linearity_zero_end_pct,
           e.repeat_5um.metrics.repeatability_nm, e.repeat_10um.metrics.repeatability_nm},
          e.table4_valid()};
}

// One seed of one plant: the calibration from fringes against the plant's own A and against
// the XL-80 calibration on the same seed, and Table 4 with each (the quick schedule, reproduce
// --quick's: every Table 4 experiment, the 230 repeatability moves kept, the same seed for both).
struct SeedFigures {
  double f_err = 0.0, x_err = 0.0;  // worst element of A from the plant's own
  double f_s = 0.0, x_s = 0.0;      // stages 2 + 3, simulated (each stage's bench from 0)
  double p_nm = 0.0;                // the two p's largest difference over 0..11 um [nm]
  std::size_t f_left_out = 0, x_left_out = 0;
  double truth_rms_nm = 0.0;  // every frame's P1..P3 from fringes against the twin's, 4 scans
  Table4Figures f_table4, x_table4;
};

// Every tracked frame of the four scans against the twin's truth (mean over the exposure, from
// the scan's frame 0) [nm RMS].
double truth_rms_nm(const FringeCalibrationOutcome& f) {
  double s2 = 0.0;
  std::size_t n = 0;
  const auto add = [&](const std::vector<FringeScanPose>& poses) {
    for (const FringeScanPose& q : poses)
      for (std::size_t j = 0; j < 3; ++j, ++n)
        s2 += std::pow(1000.0 * (q.points_um[j] - q.truth_points_um[j]), 2);
  };
  for (const FringeActuatorScanResult& a : f.actuator_scans)
    add(a.poses);
  add(f.piston_scan.poses);
  return std::sqrt(s2 / static_cast<double>(n));
}

std::optional<SeedFigures> one_seed(const Plant& pl, std::uint64_t seed) {
  TwinBenchCamera bench(seed);
  const FringeOptics optics = twin_optics(bench.scene);
  control::SemiClosedLoopParams base;
  base.sample_time_s = pl.config.twin.daq.sample_time_s;
  const FringeCalibrationOutcome f =
      calibrate_from_fringes(pl.config, base, seed, bench.cam, optics, paper_gains());
  if (!f.validity.valid) {
    ADD_FAILURE() << pl.name << ", seed " << seed << ": " << f.validity.reason;
    return std::nullopt;
  }
  const calibration::CalibrationOutcome x = calibration::calibrate(
      pl.config, base, seed, calibration::CalibrationOptions::paper_gains_only());
  const control::Mat3& own = pl.config.twin.geometry.transmission_matrix;
  SeedFigures r;
  r.f_err = worst(f.controller.matrix.a, own);
  r.x_err = worst(x.controller.matrix.a, own);
  r.x_s = x.matrix.simulated_time_s + x.polynomial.simulated_time_s;
  r.f_s = f.stage2_simulated_s + f.stage3_simulated_s;
  for (int k = 0; k <= 110; ++k) {
    const double z = 0.1 * k;
    r.p_nm = std::max(r.p_nm,
                      1000.0 * std::fabs(f.controller.polynomial(z) - x.controller.polynomial(z)));
  }
  r.truth_rms_nm = truth_rms_nm(f);
  const reproduction::Schedule schedule = reproduction::Schedule::quick();
  r.f_table4 = table4(reproduction::run_experiment_set(pl.config, f.controller, seed, schedule));
  r.x_table4 = table4(reproduction::run_experiment_set(pl.config, x.controller, seed, schedule));
  r.f_left_out = f.polynomial.saturated_points;
  r.x_left_out = x.polynomial.saturated_points;
  const auto& fp = f.controller.polynomial;
  const auto& xp = x.controller.polynomial;
  std::printf(
      "%s, seed %d: A from fringes worst element %.5f from the plant's (the XL-80's %.5f); "
      "stages 2+3 %.1f + %.1f s simulated against the XL-80's %.1f + %.1f s; %.1f s wall\n"
      "  p from fringes %.4e %.4e %.5f %.4f (%zu points, rms %.2f nm); XL-80 %.4e %.4e %.5f %.4f "
      "(rms %.2f nm); largest difference over 0..11 um %.2f nm; left out %zu / %zu; fringes vs "
      "truth %.3f nm RMS\n",
      pl.name.c_str(), static_cast<int>(seed), r.f_err, r.x_err, f.stage2_simulated_s,
      f.stage3_simulated_s, x.matrix.simulated_time_s, x.polynomial.simulated_time_s, f.wall_time_s,
      fp.p3, fp.p2, fp.p1, fp.p0, f.polynomial.command_um.size(),
      1000.0 * f.polynomial.fit.rms_residual_um, xp.p3, xp.p2, xp.p1, xp.p0,
      1000.0 * x.polynomial.fit.rms_residual_um, r.p_nm, r.f_left_out, r.x_left_out,
      r.truth_rms_nm);
  std::printf("  Table 4: fringes %.4f s %.4f %% %.3f %.3f nm; XL-80 %.4f s %.4f %% %.3f %.3f nm\n",
              r.f_table4.v[0], r.f_table4.v[1], r.f_table4.v[2], r.f_table4.v[3], r.x_table4.v[0],
              r.x_table4.v[1], r.x_table4.v[2], r.x_table4.v[3]);
  return r;
}

class FringeCalibrationPlants : public ::testing::TestWithParam<int> {};

// Seeds 1 to 8 (the acceptance figures are medians), seed 1 held to the band on its own too.
// Table 4: the median of each figure of the paper's controller calibrated from fringes lies
// within the same controller's spread over the same seeds calibrated with the XL-80 (its smallest
// to largest).
TEST_P(FringeCalibrationPlants, AWithinTheBandAndTable4WithinTheXl80sSpreadInLessTime) {
  const Plant pl = plant(GetParam());
  std::vector<double> f_err, x_err, p_nm;
  std::array<std::vector<double>, 4> fv, xv;
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    const std::optional<SeedFigures> got = one_seed(pl, seed);
    ASSERT_TRUE(got.has_value()) << "seed " << seed;
    const SeedFigures& r = *got;
    f_err.push_back(r.f_err);
    x_err.push_back(r.x_err);
    p_nm.push_back(r.p_nm);
    // no more time than the XL-80's, every seed (the scans' poses are fixed: 45.9 s)
    EXPECT_LE(r.f_s, r.x_s) << "seed " << seed;
    // at most the command 0 is left out (a PID at its lower limit: the gauges' zero a few nm
    // below the stacks' 0 V position, docs/calibration.md), as the XL-80's fit leaves it out
    EXPECT_LE(r.f_left_out, 1u) << "seed " << seed;
    // the fringes read the plate within the tracker's band (fringe_tracker_test.cpp: 0.5 nm)
    EXPECT_LT(r.truth_rms_nm, 0.5) << "seed " << seed;
    ASSERT_TRUE(r.f_table4.valid && r.x_table4.valid) << "seed " << seed;
    for (std::size_t k = 0; k < 4; ++k) {
      fv[k].push_back(r.f_table4.v[k]);
      xv[k].push_back(r.x_table4.v[k]);
    }
    if (seed == 1) {
      EXPECT_LT(r.f_err, 0.002);  // A within 0.002 of the plant's, on seed 1 alone
      // p: the XL-80's curve within 15 nm over the 11 um span (0.14 %; measured 1.6 to 2.9 nm
      // on seed 1, docs/fizeau.md)
      EXPECT_LT(r.p_nm, 15.0);
    }
  }
  std::printf(
      "%s, seeds 1 to 8: A from fringes median %.5f, worst %.5f from the plant's (the XL-80's "
      "median %.5f, worst %.5f); p from the XL-80's median %.2f, worst %.2f nm\n",
      pl.name.c_str(), median(f_err), *std::max_element(f_err.begin(), f_err.end()), median(x_err),
      *std::max_element(x_err.begin(), x_err.end()), median(p_nm),
      *std::max_element(p_nm.begin(), p_nm.end()));
  EXPECT_LT(median(f_err), 0.002);  // the acceptance figure: the median over seeds 1 to 8
  const char* names[4] = {"11 um step settling [s]", "linearity, zero-end [%]",
                          "repeatability at 5 um [nm]", "repeatability at 10 um [nm]"};
  for (std::size_t k = 0; k < 4; ++k) {
    const double mf = median(fv[k]);
    const auto [lo, hi] = std::minmax_element(xv[k].begin(), xv[k].end());
    std::printf("%-28s fringes median %.4f (%.4f to %.4f); XL-80 median %.4f (%.4f to %.4f)\n",
                names[k], mf, *std::min_element(fv[k].begin(), fv[k].end()),
                *std::max_element(fv[k].begin(), fv[k].end()), median(xv[k]), *lo, *hi);
    EXPECT_GE(mf, *lo) << names[k];
    EXPECT_LE(mf, *hi) << names[k];
  }
}

INSTANTIATE_TEST_SUITE_P(Issue29, FringeCalibrationPlants, ::testing::Values(0, 1, 2),
                         [](const ::testing::TestParamInfo<int>& i) {
                           return std::string(i.param == 0   ? "DefaultTwin"
                                              : i.param == 1 ? "GaugeGains"
                                                             : "UnequalLegs");
                         });

// A scan whose frames are lost ends the calibration with the stage, the actuator and the frame,
// and no controller to use; stage 1 skipped (holding gains) so that nothing else runs.
TEST(FringeCalibrationTest, ALostFrameEndsItWithTheStageAndTheReason) {
  ScriptedCamera cam;
  camera::CameraSettings s;
  s.width_px = s.height_px = 1;
  cam.configure(s);
  cam.lose_frame = 2;
  FringeOptics optics{psi::Mask(1, 1), 0.025, 0.025 / 120.0};
  FringeCalibrationOptions o;
  o.stages.holding_gains = control::PidGains{};
  const config::ProjectConfig config;
  control::SemiClosedLoopParams base;
  base.sample_time_s = config.twin.daq.sample_time_s;
  const FringeCalibrationOutcome r = calibrate_from_fringes(config, base, 1, cam, optics, o);
  EXPECT_FALSE(r.validity.valid);
  EXPECT_EQ(r.validity.reason, "stage 2 (matrix A), actuator 1's scan: frame 2: lost");
  EXPECT_TRUE(r.matrix.ds_um.empty());
  EXPECT_TRUE(r.piston_scan.poses.empty());
}

TEST(FringeCalibrationTest, PistonScanParamsAreRefusedByName) {
  FringePistonScanParams p;
  EXPECT_EQ(fringe_piston_scan_problem(p), "");
  p.max_um = 0.2;  // below the reference's last pose (4 lambda/8 = 0.316 um)
  EXPECT_NE(fringe_piston_scan_problem(p).find("max_um"), std::string::npos);
  p = {};
  p.max_pupil_step_nm = 200.0;
  EXPECT_NE(fringe_piston_scan_problem(p).find("max_pupil_step_nm"), std::string::npos);
  p = {};
  p.reference_frames = 2;
  EXPECT_NE(fringe_piston_scan_problem(p).find("reference_frames"), std::string::npos);
}

}  // namespace
}  // namespace piezoshift::instrument
