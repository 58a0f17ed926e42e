// The plate's pose from one frame against a reference set (frame_pose.hpp), on the twin's Fizeau
// frames (fizeau_simulation.hpp) at known poses, with the camera's noise.
#include "piezoshift/psi/frame_pose.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "piezoshift/plant/random.hpp"
#include "piezoshift/psi/fizeau_simulation.hpp"

namespace piezoshift::psi {
namespace {

struct Scene {
  FizeauParams fizeau;
  CameraParams camera;
  Mask mask = disk_mask(256, 256, 120.0);
  Map surface;
  plant::Rng rng{7};
  Scene() {
    plant::Rng surface_rng(3);
    surface = make_surface_nm(SurfaceSpec{}, mask, surface_rng);
  }
  Map frame(double piston_nm, double theta_x_urad, double theta_y_urad) {
    const PoseSample pose{0.0, piston_nm, theta_x_urad, theta_y_urad};
    return render_frame(surface, mask, fizeau, camera, std::span(&pose, 1), rng);
  }
  FramePoseReference reference() {
    std::vector<Map> frames;
    for (int k = 0; k < 5; ++k)
      frames.push_back(frame(k * fizeau.wavelength_nm / 8.0, 0.0, 0.0));
    return frame_pose_reference(frames, mask);
  }
};

// The camera's noise is about 1 % of the modulation a pixel (shot noise of 9000 e against
// 8100 e of modulation), so over the pupil's 45 000 pixels a frame's piston is known to about
// 0.01 nm (measured: 0.009 nm RMS, 0.022 nm at worst over 24 frames) and its tilts to about
// 5e-4 urad; the reference's own noise is of the same order. 0.05 nm and 0.002 urad are several
// times that, and far below what a lock needs (0.2 nm).
TEST(FramePoseTest, APoseWithinAQuarterWaveIsRecoveredToHundredthsOfANanometre) {
  Scene scene;
  const FramePoseReference ref = scene.reference();
  EXPECT_GT(ref.fringes.modulation_scale, 1000.0);
  const double cases[][3] = {
      {0.0, 0.0, 0.0}, {30.0, 0.5, -0.3}, {-40.0, -1.0, 0.8}, {12.5, 2.0, 1.5}};
  for (const auto& c : cases) {
    const FramePose p = fit_frame_pose(scene.frame(c[0], c[1], c[2]), ref, {});
    ASSERT_TRUE(p.valid) << p.reason;
    EXPECT_NEAR(p.piston_nm, c[0], 0.05);
    EXPECT_NEAR(p.theta_x_urad, c[1], 0.002);
    EXPECT_NEAR(p.theta_y_urad, c[2], 0.002);
    EXPECT_NEAR(p.contrast, 1.0, 0.01);
    EXPECT_LT(p.misfit, 0.005);  // nothing beyond the noise (max_misfit 0.02)
    EXPECT_GT(p.noise, 0.010);   // the camera's, about 0.012 of b a pixel, and the reference's
    EXPECT_LT(p.noise, 0.025);
    EXPECT_LE(p.iterations, 10);
  }
}

// Tracking: from the last pose, a drift of a whole micrometre in steps of 50 nm is followed with
// its fringe order, where one fit from the reference would alias by whole fringes.
TEST(FramePoseTest, TrackedFromTheLastPoseTheFringeOrderIsCarried) {
  Scene scene;
  const FramePoseReference ref = scene.reference();
  FramePose last;
  for (int k = 1; k <= 20; ++k) {
    const double z = 50.0 * k;
    last = fit_frame_pose(scene.frame(z, 0.1 * k, 0.0), ref, last);
    ASSERT_TRUE(last.valid) << k << ": " << last.reason;
    EXPECT_NEAR(last.piston_nm, z, 0.05) << k;  // the band above
  }
  // From the reference instead, 1 um is 3.16 half-waves away: the fit lands a whole number of
  // half-waves off, or is refused; never 1000 nm.
  const FramePose alone = fit_frame_pose(scene.frame(1000.0, 2.0, 0.0), ref, {});
  EXPECT_GT(std::fabs(alone.piston_nm - 1000.0), 100.0);
}

TEST(FramePoseTest, LostFringesAndLargeStepsAreRefusedWithTheirReason) {
  Scene scene;
  const FramePoseReference ref = scene.reference();
  // A blocked beam: the bias alone (visibility 0).
  scene.camera.visibility = 0.0;
  const FramePose dark = fit_frame_pose(scene.frame(10.0, 0.0, 0.0), ref, {});
  EXPECT_FALSE(dark.valid);
  EXPECT_NE(dark.reason.find("contrast"), std::string::npos) << dark.reason;
  // Fringes at a fifth of their contrast: still fringes, but below min_contrast 0.3.
  scene.camera.visibility = 0.18;
  const FramePose faint = fit_frame_pose(scene.frame(10.0, 0.0, 0.0), ref, {});
  EXPECT_FALSE(faint.valid);
  EXPECT_NEAR(faint.contrast, 0.2, 0.02);
  scene.camera.visibility = 0.9;
  // 100 nm of piston from the start: within the fit's basin but beyond max_step_nm (79.1).
  const FramePose far = fit_frame_pose(scene.frame(100.0, 0.0, 0.0), ref, {});
  EXPECT_FALSE(far.valid);
  EXPECT_NEAR(far.piston_nm, 100.0, 0.05);
  EXPECT_NE(far.reason.find("fringe order"), std::string::npos) << far.reason;
  // Another test surface than the reference's: a misfit.
  plant::Rng other_rng(99);
  SurfaceSpec other;
  other.zernike_nm = {{4, -60.0}, {7, 30.0}};
  scene.surface = make_surface_nm(other, scene.mask, other_rng);
  const FramePose wrong = fit_frame_pose(scene.frame(0.0, 0.0, 0.0), ref, {});
  EXPECT_FALSE(wrong.valid);
  EXPECT_FALSE(wrong.reason.empty());
}

TEST(FramePoseTest, FramesOfAnotherSizeAreRefused) {
  Scene scene;
  const FramePoseReference ref = scene.reference();
  EXPECT_THROW(fit_frame_pose(Map(10, 10, 0.0), ref, {}), std::invalid_argument);
  const std::vector<Map> three(3, Map(256, 256, 0.0));
  EXPECT_THROW(frame_pose_reference(three, scene.mask), std::invalid_argument);
}

}  // namespace
}  // namespace piezoshift::psi
