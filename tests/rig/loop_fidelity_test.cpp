// The twin's closed-loop fidelity targets (docs/twin.md, "Fidelity"), measured the way every
// figure piezoshift reports is: through the sim DAQ backend, its timing contract and the safety
// supervisor, stepped by the one loop driver (the simulated bench, bench.hpp). The open-loop
// targets are in tests/plant/twin_fidelity_test.cpp.
#include <cmath>
#include <cstring>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "piezoshift/rig/bench.hpp"

namespace piezoshift::rig {
namespace {

Bench paper_bench(std::uint64_t seed) {
  return Bench(config::ProjectConfig{}, control::SemiClosedLoopParams{}, seed);
}

// Fidelity target 5: A identified by the paper's procedure (Section 3, second step): each
// actuator moved alone in closed loop (the PID on the SGS), the three points measured by the
// interferometer (1 s static readings), least squares.
TEST(Fidelity5, PapersProcedureThroughTheLoopRecoversThePapersA) {
  Bench bench(config::ProjectConfig{}, control::SemiClosedLoopParams{}, 5);
  // Holds actuator targets S (SGS um) for `settle` seconds, then the next whole static reading.
  auto pose = [&](const Vec3& s, double settle) {
    bench.drive_actuators(s);
    bench.run(settle);
    return bench.measure_static().points_um;
  };
  const Vec3 base{2.0, 2.0, 2.0};
  const Vec3 z0 = pose(base, 2.0);
  std::vector<Vec3> ds, dz;
  for (const double a : {3.0, 6.0}) {
    for (std::size_t i = 0; i < 3; ++i) {
      Vec3 s = base;
      s[i] += a;
      const Vec3 z = pose(s, 1.0);
      ds.push_back({s[0] - base[0], s[1] - base[1], s[2] - base[2]});
      dz.push_back({z[0] - z0[0], z[1] - z0[1], z[2] - z0[2]});
      pose(base, 0.5);
    }
  }
  ASSERT_FALSE(bench.faulted()) << runtime::to_string(bench.fault().reason);
  // dS = A dZ for every pose: A^T = argmin || dZ X - dS ||
  Eigen::MatrixXd zm(static_cast<Eigen::Index>(dz.size()), 3), sm(zm.rows(), 3);
  for (Eigen::Index r = 0; r < zm.rows(); ++r)
    for (Eigen::Index c = 0; c < 3; ++c) {
      zm(r, c) = dz[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)];
      sm(r, c) = ds[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)];
    }
  const Eigen::Matrix3d a = zm.colPivHouseholderQr().solve(sm).transpose();
  const control::Mat3 paper = control::TransmissionMatrix{}.a;
  double worst = 0.0;
  for (Eigen::Index r = 0; r < 3; ++r)
    for (Eigen::Index c = 0; c < 3; ++c) {
      const double d = a(r, c) - paper[static_cast<std::size_t>(r)][static_cast<std::size_t>(c)];
      EXPECT_NEAR(d, 0.0, 0.05) << "A(" << r + 1 << "," << c + 1 << ")";
      worst = std::max(worst, std::fabs(d));
    }
  RecordProperty("max_abs_error", std::to_string(worst));
  EXPECT_LT(worst, 0.01);  // what the twin actually gives: the SGS bow and noise are small
}

// Fidelity target 6: one seed, one output, bit for bit; another seed, another output.
std::vector<double> closed_loop_record(std::uint64_t seed) {
  Bench bench = paper_bench(seed);
  std::vector<double> record;
  for (int k = 0; k < 3000; ++k) {
    const double zd = k < 500 ? 1.0 : 9.0;
    bench.drive_points(Vec3{zd, zd, zd});
    bench.run(bench.sample_time_s());
    const plant::TwinTruth& t = bench.twin().truth();
    const plant::InterferometerReading& r = bench.twin().interferometer();
    for (std::size_t i = 0; i < 3; ++i) {
      record.push_back(bench.last_cycle().ai_V[i]);
      record.push_back(t.points_um[i]);
      record.push_back(r.dynamic_um[i]);
      record.push_back(r.static_um[i]);
    }
  }
  return record;
}

TEST(Fidelity6, SameSeedGivesIdenticalOutputsBitForBit) {
  const std::vector<double> a = closed_loop_record(42), b = closed_loop_record(42);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)), 0);
}

TEST(Fidelity6, DifferentSeedsGiveDifferentOutputs) {
  const std::vector<double> a = closed_loop_record(42), b = closed_loop_record(43);
  std::size_t differ = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    differ += a[i] != b[i] ? 1 : 0;
  EXPECT_GT(differ, a.size() / 2);
}

// 10 um, not the paper's 11: with the paper's own p (fitted to the paper's stage, not to the
// twin) an 11 um request asks p(11) = 11.35 um of every leg, beyond the twin's short leg (the
// per-leg stroke identified from Section 4.1, docs/twin.md). The reproduction's 11 um step runs
// with the p calibrated on the twin (tests/reproduction).
TEST(ClosedLoop, PapersControllerSettlesATenMicronStepWellWithinPointThreeSeconds) {
  Bench bench = paper_bench(11);
  std::vector<double> z;
  std::uint8_t saturated = 0;
  const auto record = [&](const Bench& b) {
    saturated |= b.last_output().saturated_mask;
    z.push_back(b.twin().interferometer().dynamic_um[0]);
  };
  bench.drive_points(Vec3{0.0, 0.0, 0.0});
  bench.run(0.5, record);
  bench.drive_points(Vec3{10.0, 10.0, 10.0});
  bench.run(1.0, record);
  ASSERT_EQ(z.size(), 1500U);
  ASSERT_FALSE(bench.faulted()) << runtime::to_string(bench.fault().reason);
  double z_inf = 0.0, z_0 = 0.0;
  for (int k = 1400; k < 1500; ++k)
    z_inf += z[static_cast<std::size_t>(k)] / 100.0;
  for (int k = 400; k < 500; ++k)
    z_0 += z[static_cast<std::size_t>(k)] / 100.0;
  int last_out = 500;
  for (int k = 500; k < 1500; ++k)
    if (std::fabs(z[static_cast<std::size_t>(k)] - z_inf) > 0.02 * (z_inf - z_0))
      last_out = k;
  const double settle_s = (last_out - 500 + 1) * 1e-3;
  EXPECT_LT(settle_s, 0.3);
  EXPECT_LT(settle_s, 0.06);  // what it is: ~35 ms
  EXPECT_NEAR(z_inf - z_0, 10.0 * 1.014 + 0.000389 * 100 - 0.0001009 * 1000, 0.05);  // p(10) - p(0)
  EXPECT_EQ(saturated & 0x7, 0);
  RecordProperty("settling_2pct_s", std::to_string(settle_s));
}

}  // namespace
}  // namespace piezoshift::rig
