// Tilt-aware AIA on frames made independently of the algorithm's model: a fringe
// generator of its own (cos of the surface's phase + each frame's piston and tilt plane, Gaussian
// noise from std::mt19937), not psi::render_frame, and not the algorithm's pupil coordinates.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "piezoshift/psi/phase_algorithms.hpp"
#include "piezoshift/psi/surface_metrics.hpp"

namespace piezoshift::psi {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kNmPerRad = 632.8 / (4.0 * kPi);

double wrap(double a) {
  return std::remainder(a, 2.0 * kPi);
}

// One sequence: the frames, the truth and the frame planes (phase at pixel (i, j) is
// piston + tip v + tilt u with u, v in [-1, 1] over the disk's radius, v up).
struct Sequence {
  int size = 0;
  Mask mask;
  Map phi;
  std::vector<double> piston, tip, tilt;
  std::vector<Map> frames;
};

struct Draw {
  double step_spread_rad = 0.2;  //!< std of each step's error (truncated at 2 std)
  double max_tilt_rad = 1.0;     //!< largest plane value at the pupil edge, any direction
  double noise = 0.01;           //!< Gaussian intensity noise, of the mean (A = 1, B = 0.8)
  double step_offset_rad = 0.0;  //!< added to every step after the first (a commanded miss)
};

Sequence make_sequence(int size, unsigned seed, const Draw& d) {
  std::mt19937 gen(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Sequence s;
  s.size = size;
  const double c = 0.5 * (size - 1), r = 0.5 * size;
  s.mask = Mask(size, size, 0);
  s.phi = Map(size, size, 0.0);
  // the surface: 2.5 waves of defocus, 1.5 of astigmatism, 0.8 of coma (rad = 2 pi waves)
  for (int j = 0; j < size; ++j)
    for (int i = 0; i < size; ++i) {
      const double u = (i - c) / r, v = (c - j) / r, rho2 = u * u + v * v;
      s.mask.v[static_cast<std::size_t>(j * size + i)] = rho2 <= 1.0 ? 1 : 0;
      s.phi.at(i, j) =
          2.0 * kPi * (2.5 * rho2 + 1.5 * (u * u - v * v) + 0.8 * (3.0 * rho2 - 2.0) * v);
    }
  for (int k = 0; k < 5; ++k) {
    double e = 0.0;
    if (k > 0)
      do
        e = d.step_spread_rad * normal(gen);
      while (std::fabs(e) > 2.0 * d.step_spread_rad);
    const double mag = d.max_tilt_rad * unit(gen), dir = 2.0 * kPi * unit(gen);
    s.piston.push_back(k * kPi / 2.0 + e + (k > 0 ? d.step_offset_rad : 0.0));
    s.tip.push_back(mag * std::sin(dir));
    s.tilt.push_back(mag * std::cos(dir));
  }
  for (int k = 0; k < 5; ++k) {
    Map f(size, size);
    for (int j = 0; j < size; ++j)
      for (int i = 0; i < size; ++i) {
        const double u = (i - c) / r, v = (c - j) / r;
        const double shift = s.piston[k] + s.tip[k] * v + s.tilt[k] * u;
        f.at(i, j) = 1.0 + 0.8 * std::cos(s.phi.at(i, j) + shift) + d.noise * normal(gen);
      }
    s.frames.push_back(std::move(f));
  }
  return s;
}

// The noise floor: per pixel least squares knowing every frame's true plane.
Map oracle_phase(const Sequence& s) {
  const double c = 0.5 * (s.size - 1), r = 0.5 * s.size;
  Map out(s.size, s.size, std::nan(""));
  for (int j = 0; j < s.size; ++j)
    for (int i = 0; i < s.size; ++i) {
      if (!s.mask.v[static_cast<std::size_t>(j * s.size + i)])
        continue;
      Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
      Eigen::Vector3d y = Eigen::Vector3d::Zero();
      for (std::size_t k = 0; k < s.frames.size(); ++k) {
        const double d = s.piston[k] + s.tip[k] * (c - j) / r + s.tilt[k] * (i - c) / r;
        const Eigen::Vector3d row(1.0, std::cos(d), -std::sin(d));
        M += row * row.transpose();
        y += row * s.frames[k].at(i, j);
      }
      const Eigen::Vector3d u = M.ldlt().solve(y);
      out.at(i, j) = std::atan2(u(2), u(1));
    }
  return out;
}

// Surface error [nm RMS] of a wrapped phase against the truth, piston and tilt removed (every
// method refers its phase to some frame's plane). The error is wrapped about its circular mean,
// fine while it stays within +-pi of it.
double error_nm(const Map& measured, const Sequence& s) {
  Map e(s.size, s.size, std::nan(""));
  double sn = 0.0, cs = 0.0;
  for (std::size_t p = 0; p < s.mask.size(); ++p)
    if (s.mask.v[p] && std::isfinite(measured.v[p])) {
      e.v[p] = wrap(measured.v[p] - s.phi.v[p]);
      sn += std::sin(e.v[p]);
      cs += std::cos(e.v[p]);
    }
  const double centre = std::atan2(sn, cs);
  Mask valid(s.size, s.size, 0);
  for (std::size_t p = 0; p < s.mask.size(); ++p)
    if (std::isfinite(e.v[p])) {
      e.v[p] = centre + wrap(e.v[p] - centre);
      valid.v[p] = 1;
    }
  return kNmPerRad * surface_figures(remove_terms(e, valid, Removal::kTilt), valid, false).rms;
}

PhaseResult run(Algorithm a, const Sequence& s) {
  PhaseOptions o;
  o.algorithm = a;
  return wrapped_phase(s.frames, s.mask, o);
}

// Frames of sequence s with a second harmonic of the fringe added (a Fizeau of high-reflectance
// surfaces, or a camera's nonlinearity): not the two-beam model the fits assume.
std::vector<Map> with_second_harmonic(const Sequence& s, double fraction) {
  std::vector<Map> out = s.frames;
  const double c = 0.5 * (s.size - 1), r = 0.5 * s.size;
  for (std::size_t k = 0; k < out.size(); ++k)
    for (int j = 0; j < s.size; ++j)
      for (int i = 0; i < s.size; ++i) {
        const double shift = s.piston[k] + s.tip[k] * (c - j) / r + s.tilt[k] * (i - c) / r;
        out[k].at(i, j) += fraction * 0.8 * std::cos(2.0 * (s.phi.at(i, j) + shift));
      }
  return out;
}

struct Outcome {
  double floor_nm, tilt_nm, five_nm;
  PhaseResult tilt;
};

Outcome analyse(const Sequence& s) {
  Outcome o{error_nm(oracle_phase(s), s), 0.0, 0.0, run(Algorithm::kTiltAia, s)};
  o.tilt_nm = error_nm(o.tilt.phase_rad, s);
  o.five_nm = error_nm(run(Algorithm::kHariharan5, s).phase_rad, s);
  return o;
}

// The noise floor is the same frames' error with every frame's true plane known (oracle_phase):
// what any method that must also find the planes can at best reach. 1 % intensity noise of the
// mean (sigma_I / B = 0.0125) puts it at ~0.42 nm RMS here.
TEST(TiltAiaIndependentTest, OneSequenceReachesItsNoiseFloor) {
  const Outcome o = analyse(make_sequence(128, 1, Draw{}));
  EXPECT_TRUE(o.tilt.converged) << o.tilt.reason;
  EXPECT_EQ(o.tilt.reason, "");
  // measured 1.000 x the floor; 1.05 leaves room for the last digits of the iteration
  EXPECT_LT(o.tilt_nm, 1.05 * o.floor_nm) << "floor " << o.floor_nm;
  EXPECT_GT(o.five_nm, 5.0 * o.floor_nm) << "floor " << o.floor_nm;  // 9.6 nm: the tilts matter
  // the residual is the noise: 0.0079 of the modulation (sigma_I / B sqrt(2/5) = 0.0079)
  EXPECT_NEAR(o.tilt.residual_rms, 0.0079, 0.0008);
  EXPECT_NEAR(o.tilt.noise_rms, o.tilt.residual_rms, 0.0005);
}

// The acceptance figure of tilt-aware AIA: 20 seeded sequences, 256 px pupil, steps k pi/2 plus
// errors of 0.2 rad std (truncated at 0.4), each frame tilted by up to 1 rad at the pupil edge in
// any direction: tilt-aia within 2 x its noise floor on every one, or not converged; never
// converged on a surface worse than the 5-frame's. Measured: all 20 converged at 1.000 x the floor
// (0.41 to 0.49 nm), the 5-frame 2.4 to 9.6 nm. So that the test cannot pass by giving up, at least
// 18 of the 20 must converge.
TEST(TiltAiaIndependentTest, TwentySeededSequencesReachTheFloorOrSayNot) {
  int converged = 0;
  double worst_ratio = 0.0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const Outcome o = analyse(make_sequence(256, seed, Draw{}));
    if (!o.tilt.converged)
      continue;
    ++converged;
    worst_ratio = std::max(worst_ratio, o.tilt_nm / o.floor_nm);
    EXPECT_LT(o.tilt_nm, 2.0 * o.floor_nm) << seed << " floor " << o.floor_nm;
    EXPECT_LT(o.tilt_nm, o.five_nm) << seed;
  }
  EXPECT_GE(converged, 18);
  std::printf("tilt-aia: %d of 20 converged, worst %.4f x the noise floor\n", converged,
              worst_ratio);
}

// Steps 1.5 rad from the commanded ones: the fit finds the frames' true steps, which are not the
// sequence that was commanded, and says so.
TEST(TiltAiaIndependentTest, StepsFarFromTheCommandedAreNotConverged) {
  Draw d;
  d.step_offset_rad = 1.5;
  const Sequence s = make_sequence(96, 3, d);
  for (const Algorithm a : {Algorithm::kAia, Algorithm::kTiltAia}) {
    const PhaseResult r = run(a, s);
    EXPECT_FALSE(r.converged) << algorithm_name(a);
    EXPECT_NE(r.reason.find("from the commanded"), std::string::npos) << r.reason;
  }
}

// Frames of noise alone, and frames with a strong second harmonic: no fit of the model is right.
TEST(TiltAiaIndependentTest, RandomFramesAndFramesOutsideTheModelAreNotConverged) {
  std::mt19937 gen(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Mask mask(64, 64, 1);
  std::vector<Map> noise(5, Map(64, 64));
  for (Map& f : noise)
    for (double& v : f.v)
      v = unit(gen);
  PhaseOptions o;
  for (const Algorithm a : {Algorithm::kAia, Algorithm::kTiltAia}) {
    o.algorithm = a;
    const PhaseResult r = wrapped_phase(noise, mask, o);
    EXPECT_FALSE(r.converged) << algorithm_name(a);
    EXPECT_NE(r.reason, "") << algorithm_name(a);
  }
  const Sequence s = make_sequence(96, 4, Draw{});
  o.algorithm = Algorithm::kTiltAia;
  const PhaseResult r = wrapped_phase(with_second_harmonic(s, 0.2), s.mask, o);
  EXPECT_FALSE(r.converged);
  EXPECT_NE(r.reason.find("differ from the fitted model"), std::string::npos) << r.reason;
}

}  // namespace
}  // namespace piezoshift::psi
