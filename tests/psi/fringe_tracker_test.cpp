// The plate's pose from fringes (psi/fringe_tracker.hpp) against the twin's truth: frames
// rendered by psi::render_frame on the default scene (surface, 256 px camera, shot and read
// noise, 12 bits) at known poses, fed to the tracker without the poses.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <vector>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/plant/geometry.hpp"
#include "piezoshift/plant/random.hpp"
#include "piezoshift/psi/fizeau_simulation.hpp"
#include "piezoshift/psi/fringe_tracker.hpp"

namespace piezoshift::psi {
namespace {

struct Scene {
  FizeauParams fizeau{};
  CameraParams camera{};
  Mask mask;
  Map surface_nm;
  kinematics::TripodGeometry tripod{plant::make_twin_geometry({}).points};

  // size_px: 256 is the default camera; 128 (pupil 60 px) for the tests of refusals, which do
  // not depend on the pixel count and then run tilt-aia in a quarter of the time
  explicit Scene(std::uint64_t seed, int size_px = 256) {
    if (size_px != fizeau.width_px) {
      fizeau.pupil_radius_px *= static_cast<double>(size_px) / fizeau.width_px;
      fizeau.width_px = fizeau.height_px = size_px;
    }
    mask = disk_mask(fizeau.width_px, fizeau.height_px, fizeau.pupil_radius_px);
    plant::Rng rng(seed);
    surface_nm = make_surface_nm(SurfaceSpec{}, mask, rng);
  }
  FringeTrackerParams params() const {
    FringeTrackerParams p;
    p.wavelength_nm = fizeau.wavelength_nm;
    p.plate_m_per_px = fizeau.pupil_radius_m / fizeau.pupil_radius_px;
    p.points = tripod.points();
    return p;
  }
};

struct Tracked {
  std::vector<FringePose> poses;
  double p_rms_nm = 0.0;        // P1..P3 against truth, over every frame and point
  double s_first_window = 0.0;  // the push that resolved the first window
  double s_per_frame = 0.0;     // the other pushes, per frame
};

// Renders each truth pose (a still plate), feeds the frames in order, and compares.
Tracked track(const Scene& s, const std::vector<kinematics::PlatePose>& truth, std::uint64_t seed,
              FringeTrackerParams p) {
  FringeTracker tracker(s.mask, p);
  plant::Rng rng(seed);
  Tracked run;
  double seconds = 0.0;
  for (const kinematics::PlatePose& t : truth) {
    const PoseSample pose{0.0, 1000.0 * t.z_um, t.theta_x_urad, t.theta_y_urad};
    const Map frame = render_frame(s.surface_nm, s.mask, s.fizeau, s.camera,
                                   std::span<const PoseSample>(&pose, 1), rng);
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<FringePose> got = tracker.push(frame);
    const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    seconds += dt;
    if (got.size() == static_cast<std::size_t>(p.window_frames))
      run.s_first_window = dt;
    for (FringePose& r : got)
      run.poses.push_back(std::move(r));
  }
  run.s_per_frame = (seconds - run.s_first_window) /
                    static_cast<double>(truth.size() - static_cast<std::size_t>(p.window_frames));
  double s2 = 0.0;
  std::size_t n = 0;
  const kinematics::PointDisplacements p0 = s.tripod.inverse(truth[0]);
  for (const FringePose& r : run.poses) {
    if (!r.valid)
      continue;
    const kinematics::PointDisplacements pt = s.tripod.inverse(truth[r.frame]);
    for (int j = 0; j < 3; ++j) {
      s2 += std::pow(1000.0 * (r.points_um[j] - (pt[j] - p0[j])), 2);
      ++n;
    }
  }
  run.p_rms_nm = n ? std::sqrt(s2 / static_cast<double>(n)) : NAN;
  return run;
}

// Steps of nominal_nm +- 25 %, unknown to the tracker (a uniform draw per frame).
std::vector<double> uneven_steps(int frames, double nominal_nm, std::uint64_t seed) {
  plant::Rng rng(seed);
  std::vector<double> z{0.0};
  for (int k = 1; k < frames; ++k)
    z.push_back(z.back() + nominal_nm * (0.75 + 0.5 * rng.uniform()));
  return z;
}

// The band for P1..P3: the camera's noise carried to the points. Per pixel the intensity noise
// is sqrt(N_e) (shot) and 10 e (read) over a modulation B = V N_e = 0.9 * 9000 e: 95 e / 8100 e
// = 0.0117 of B, a phase noise of 0.0117 rad per pixel and frame. Over the ~45000 pupil pixels
// a frame's piston is known to 0.0117 sqrt(2 / 45000) = 7.8e-5 rad (0.004 nm), its tip and tilt
// (pupil coordinates, <y^2> = 1/4) to twice that, carried to P_j at up to 1.15 actuator radii
// (0.0575 m, 2.3 pupil radii): about 0.02 nm. The frame's own noise and the reference window's
// add alike, so a few hundredths of a nanometre RMS; the tilt-aia fit's settling (tolerance 1e-6
// rad) is far below. The band, 0.5 nm RMS and 1.5 nm for any point, is 20 times that: it
// catches a lost fringe order (158 nm), a wrong sign or scale (percent of micrometres), and a
// plane misread by a tenth of a radian (about 10 nm at the points).
constexpr double kBandRmsNm = 0.5;
constexpr double kBandMaxNm = 1.5;

void expect_within_band(const Scene& s, const std::vector<kinematics::PlatePose>& truth,
                        const Tracked& run) {
  ASSERT_EQ(run.poses.size(), truth.size());  // 5 + 4 n frames: every one resolved
  const kinematics::PointDisplacements p0 = s.tripod.inverse(truth[0]);
  for (const FringePose& r : run.poses) {
    ASSERT_TRUE(r.valid) << "frame " << r.frame << ": " << r.reason;
    const kinematics::PointDisplacements pt = s.tripod.inverse(truth[r.frame]);
    for (int j = 0; j < 3; ++j)
      EXPECT_NEAR(1000.0 * r.points_um[j], 1000.0 * (pt[j] - p0[j]), kBandMaxNm)
          << "frame " << r.frame << " P" << j + 1;
  }
  EXPECT_LT(run.p_rms_nm, kBandRmsNm);
}

TEST(FringeTrackerTest, PistonScanOfThreeMicrometresGivesP1P2P3WithinTheNoiseBand) {
  const Scene s(1);
  std::vector<kinematics::PlatePose> truth;
  for (const double z_nm : uneven_steps(41, 75.0, 11))
    truth.push_back({1e-3 * z_nm, 0.0, 0.0});
  ASSERT_GT(truth.back().z_um, 2.5);
  const Tracked run = track(s, truth, 21, s.params());
  std::printf(
      "piston scan: %zu frames, P rms %.4f nm, %.2f s first window, %.4f s per frame after\n",
      truth.size(), run.p_rms_nm, run.s_first_window, run.s_per_frame);
  expect_within_band(s, truth, run);
  // the piston itself, to the same band: the fringe order carried over 38 fringes
  EXPECT_NEAR(run.poses.back().piston_nm, 1000.0 * truth.back().z_um, kBandMaxNm);
}

TEST(FringeTrackerTest, OneActuatorScanGivesP1P2P3WithinTheNoiseBand) {
  // The paper's stage 1: actuator 1 alone, so P1 rises and the plate pivots (on the twin P1..P3
  // are not the legs, so all three points move; the pose is what one leg's motion makes).
  // It starts from a reference sequence of four lambda/8 piston steps (the instrument's PSI
  // sequence): tilt-aia cannot take its reference from the one-leg frames themselves, which
  // pivot about the line of the other two legs, so that part of the pupil sees no phase shift.
  const Scene s(2);
  const plant::TwinGeometry g = plant::make_twin_geometry({});
  const kinematics::TripodGeometry legs(g.actuators);
  std::vector<kinematics::PlatePose> truth;
  for (int k = 0; k < 4; ++k)
    truth.push_back({1e-3 * 79.1 * k, 0.0, 0.0});
  const std::vector<double> leg_nm = uneven_steps(38, 120.0, 12);
  for (std::size_t k = 1; k < leg_nm.size(); ++k) {
    kinematics::PlatePose p = legs.forward({1e-3 * leg_nm[k], 0.0, 0.0});
    p.z_um += 3e-3 * 79.1;
    truth.push_back(p);
  }
  ASSERT_GT(std::fabs(truth.back().theta_x_urad), 50.0);  // 25 rad at the pupil edge
  const Tracked run = track(s, truth, 22, s.params());
  std::printf(
      "one-actuator scan: %zu frames, P rms %.4f nm, %.2f s first window, %.4f s per frame after\n",
      truth.size(), run.p_rms_nm, run.s_first_window, run.s_per_frame);
  expect_within_band(s, truth, run);
}

TEST(FringeTrackerTest, WindowsMethodGivesAPistonScanWithinTheNoiseBand) {
  // tilt-aia on every window (hop 4), anchored to the first window's phase: 25 frames, 1.8 um
  const Scene s(8);
  std::vector<kinematics::PlatePose> truth;
  for (const double z_nm : uneven_steps(25, 75.0, 18))
    truth.push_back({1e-3 * z_nm, 0.0, 0.0});
  FringeTrackerParams p = s.params();
  p.method = FringeMethod::kWindows;
  const Tracked run = track(s, truth, 28, p);
  std::printf("windows, piston scan: %zu frames, P rms %.4f nm, %.4f s per frame after\n",
              truth.size(), run.p_rms_nm, run.s_per_frame);
  expect_within_band(s, truth, run);
}

TEST(FringeTrackerTest, AStepPastTheLimitIsRefusedWithItsReasonAndTheOrderStaysLost) {
  const Scene s(3, 128);
  std::vector<kinematics::PlatePose> truth;
  for (int k = 0; k < 9; ++k)  // 70 nm steps, then one of 140 nm (2.78 rad, beyond 0.75 pi)
    truth.push_back({1e-3 * (70.0 * k + (k >= 6 ? 70.0 : 0.0)), 0.0, 0.0});
  truth.push_back({truth.back().z_um + 0.07, 0.0, 0.0});
  const Tracked run = track(s, truth, 23, s.params());
  ASSERT_EQ(run.poses.size(), truth.size());
  for (std::size_t f = 0; f < 6; ++f)
    EXPECT_TRUE(run.poses[f].valid) << f << ": " << run.poses[f].reason;
  EXPECT_FALSE(run.poses[6].valid);
  EXPECT_NE(run.poses[6].reason.find("step from frame 5 to 6 reaches 2."), std::string::npos)
      << run.poses[6].reason;
  EXPECT_TRUE(std::isnan(run.poses[6].points_um[0]));
  for (std::size_t f = 7; f < truth.size(); ++f) {
    EXPECT_FALSE(run.poses[f].valid);
    EXPECT_NE(run.poses[f].reason.find("fringe order lost at frame 6"), std::string::npos)
        << run.poses[f].reason;
  }
}

TEST(FringeTrackerTest, AStepPastAQuarterWaveReadAsItsAliasIsRefused) {
  const Scene s(4, 128);
  std::vector<kinematics::PlatePose> truth;
  for (int k = 0; k < 9; ++k)  // 60 nm steps, then 230 nm (1.46 pi: reads as -0.54 pi)
    truth.push_back({1e-3 * (60.0 * k + (k >= 6 ? 170.0 : 0.0)), 0.0, 0.0});
  const Tracked run = track(s, truth, 24, s.params());
  ASSERT_EQ(run.poses.size(), truth.size());
  EXPECT_TRUE(run.poses[5].valid) << run.poses[5].reason;
  EXPECT_FALSE(run.poses[6].valid);
  EXPECT_NE(run.poses[6].reason.find("step from frame 5 to 6 is -1."), std::string::npos)
      << run.poses[6].reason;
  EXPECT_NE(run.poses[6].reason.find("read as its alias"), std::string::npos)
      << run.poses[6].reason;
}

TEST(FringeTrackerTest, ADescentIsReadAsOneWhenTheFirstDirectionSaysSo) {
  // Fringes alone cannot tell a descent from an ascent (phi -> -phi is the same data): told
  // the first window's direction, the tracker gets the descent; told wrong, its mirror image.
  const Scene s(9, 128);
  std::vector<kinematics::PlatePose> truth;
  for (int k = 0; k < 13; ++k)
    truth.push_back({-1e-3 * 70.0 * k, 0.05 * k, 0.0});
  FringeTrackerParams p = s.params();
  p.first_direction = -1;
  const Tracked down = track(s, truth, 29, p);
  ASSERT_EQ(down.poses.size(), truth.size());
  for (const FringePose& r : down.poses)
    ASSERT_TRUE(r.valid) << r.frame << ": " << r.reason;
  // 128 px: a quarter of the pixels, twice the noise of the 256 px band's estimate
  EXPECT_LT(down.p_rms_nm, 2.0 * kBandRmsNm);
  EXPECT_NEAR(down.poses.back().piston_nm, -840.0, 1.0);
  p.first_direction = +1;
  const Tracked up = track(s, truth, 29, p);
  ASSERT_TRUE(up.poses.back().valid) << up.poses.back().reason;
  EXPECT_NEAR(up.poses.back().piston_nm, 840.0, 1.0);
  EXPECT_NEAR(up.poses.back().theta_x_urad, -0.6, 0.01);
}

TEST(FringeTrackerTest, ATiltJumpBeyondTheFitsReachIsRefused) {
  // After the reference sequence the plate rests, then tips by 6 urad in one frame: 3.0 rad at
  // the pupil edge, beyond what the fit started from the plate at rest reaches (4 urad, 2.0 rad
  // at the edge, is followed: docs/fizeau.md).
  const Scene s(10, 128);
  std::vector<kinematics::PlatePose> truth;
  for (int k = 0; k < 5; ++k)
    truth.push_back({1e-3 * 79.1 * k, 0.0, 0.0});
  for (int k = 5; k < 10; ++k)
    truth.push_back({1e-3 * 79.1 * 4, k >= 8 ? 6.0 : 0.0, 0.0});
  const Tracked run = track(s, truth, 30, s.params());
  ASSERT_EQ(run.poses.size(), truth.size());
  EXPECT_TRUE(run.poses[7].valid) << run.poses[7].reason;
  EXPECT_NEAR(run.poses[7].piston_nm, 316.4, 1.0);
  EXPECT_FALSE(run.poses[8].valid);
  EXPECT_NE(run.poses[8].reason.find("frame 8: the "), std::string::npos) << run.poses[8].reason;
  EXPECT_NE(run.poses[8].reason.find("tilt changed beyond the fit's reach"), std::string::npos)
      << run.poses[8].reason;
}

TEST(FringeTrackerTest, FaintFringesAreRefusedAsLowModulation) {
  Scene s(5, 128);
  s.camera.visibility = 0.02;
  std::vector<kinematics::PlatePose> truth;
  for (int k = 0; k < 5; ++k)
    truth.push_back({1e-3 * 79.0 * k, 0.0, 0.0});
  const Tracked run = track(s, truth, 25, s.params());
  ASSERT_EQ(run.poses.size(), 5U);
  EXPECT_FALSE(run.poses[0].valid);
  EXPECT_NE(run.poses[0].reason.find("modulation too low"), std::string::npos)
      << run.poses[0].reason;
}

TEST(FringeTrackerTest, BadParamsAndFramesAreRefusedByName) {
  const Scene s(6, 128);
  FringeTrackerParams p = s.params();
  p.max_step_rad = 4.0;
  try {
    FringeTracker t(s.mask, p);
    FAIL() << "accepted max_step_rad = 4";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("max_step_rad"), std::string::npos) << e.what();
  }
  p = s.params();
  p.hop_frames = 5;
  EXPECT_THROW(FringeTracker(s.mask, p), core::InputError);
  FringeTracker t(s.mask, s.params());
  EXPECT_THROW(t.push(Map(10, 10)), std::invalid_argument);
}

}  // namespace
}  // namespace piezoshift::psi
