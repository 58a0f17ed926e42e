// The hold's summary (hold_summary.hpp) and the lock of a measurement on the twin's scene
// (measurement_lock.hpp), on records and scenes built by hand: every figure by hand from them.
#include "piezoshift/instrument/hold_summary.hpp"
#include "piezoshift/camera/camera_config.hpp"
#include "piezoshift/camera/twin_camera.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/instrument/measurement_lock.hpp"

namespace piezoshift::instrument {
namespace {

ExposureRecord record(double trigger_time_s, double truth_piston_nm, std::string lock_state) {
  ExposureRecord e;
  e.trigger_time_s = trigger_time_s;
  e.commanded_piston_nm = 0.0;
  e.has_truth = true;
  e.truth_piston_nm = truth_piston_nm;
  e.lock_state = std::move(lock_state);
  return e;
}

// Frame 0 at 10 nm of truth: the set point. The hold's paths 1, 3 | -2, -2 | 5, 7 nm over the
// seconds [0, 1), [1, 2) and the partial [2, 2.2].
SequenceResult held() {
  SequenceResult r;
  r.exposures.push_back(record(0.0, 10.0, ""));
  const double t[] = {0.0, 0.5, 1.0, 1.5, 2.0, 2.2};
  const double path[] = {1.0, 3.0, -2.0, -2.0, 5.0, 7.0};
  for (int i = 0; i < 6; ++i)
    r.hold.push_back(record(t[i], 10.0 + path[i], i < 4 ? "locked" : "holding"));
  return r;
}

TEST(HoldSummaryTest, FiguresOfAHoldByHand) {
  const HoldSummary h = hold_summary(held());
  EXPECT_EQ(h.frames, 6u);
  EXPECT_DOUBLE_EQ(h.span_s, 2.2);
  ASSERT_TRUE(h.frame_interval_s);
  EXPECT_DOUBLE_EQ(*h.frame_interval_s, 2.2 / 5.0);
  EXPECT_EQ(h.path_error_nm, (std::vector<double>{1.0, 3.0, -2.0, -2.0, 5.0, 7.0}));
  ASSERT_TRUE(h.path_error_rms_nm && h.path_error_max_nm && h.path_error_1s_means_rms_nm);
  EXPECT_NEAR(*h.path_error_rms_nm, std::sqrt(92.0 / 6.0), 1e-12);
  EXPECT_DOUBLE_EQ(*h.path_error_max_nm, 7.0);
  // Means 2 and -2 over the whole seconds; the partial last second (6) left out.
  EXPECT_NEAR(*h.path_error_1s_means_rms_nm, 2.0, 1e-12);
  EXPECT_EQ(h.lock_states.at("locked"), 4u);
  EXPECT_EQ(h.lock_states.at("holding"), 2u);
}

TEST(HoldSummaryTest, WithoutTruthOrHoldThereIsNoFigure) {
  SequenceResult r = held();
  r.hold[3].has_truth = false;  // one record without truth: no path at all, never a partial one
  const HoldSummary h = hold_summary(r);
  EXPECT_TRUE(h.path_error_nm.empty());
  EXPECT_FALSE(h.path_error_rms_nm || h.path_error_max_nm || h.path_error_1s_means_rms_nm);
  EXPECT_EQ(h.frames, 6u);
  const HoldSummary none = hold_summary(SequenceResult{});
  EXPECT_EQ(none.frames, 0u);
  EXPECT_FALSE(none.frame_interval_s || none.path_error_rms_nm);
  EXPECT_TRUE(none.lock_states.empty());
}

SequenceParams hariharan5() {
  SequenceParams p;
  p.steps_rad = commanded_steps(psi::Algorithm::kHariharan5, {}, "steps");
  return p;
}

// The lock takes the pupil the front end gives (the twin camera's scene's), or none (the session
// finds it in the reference frames' modulation), with the config's radius on the plate.
TEST(MeasurementLockTest, TheLockTakesThePupilGivenAndTheTwinsPoints) {
  camera::CameraSettings settings;
  settings.width_px = settings.height_px = 64;
  const camera::TwinScene scene = camera::make_twin_scene(
      {}, camera::measurement_optics(settings, camera::CameraConfig{}.pupil_radius_m, 632.8), 1);
  const plant::GeometryParams geometry;
  const LockSetup l =
      measurement_lock_setup(scene.mask, 0.04, geometry, {}, 2.5, hariharan5(), "lock");
  EXPECT_EQ(l.mask.count(), scene.mask.count());
  EXPECT_EQ(l.pupil_radius_m, 0.04);
  ASSERT_TRUE(l.tripod);
  EXPECT_EQ(l.retake_s, 2.5);
  const LockSetup other = measurement_lock_setup({}, 0.04, geometry, {}, 2.5, hariharan5(), "lock");
  EXPECT_EQ(other.mask.size(), 0u);
  EXPECT_EQ(other.pupil_radius_m, 0.04);
  ASSERT_TRUE(other.tripod);
  // Refusals name the front end's option.
  const auto refused = [&](const psi::Mask& m, double retake_s, const SequenceParams& p,
                           const std::string& piece) {
    try {
      (void)measurement_lock_setup(m, 0.025, geometry, {}, retake_s, p, "--lock");
      ADD_FAILURE() << piece;
    } catch (const core::InputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("--lock: ", 0), 0u) << e.what();
      EXPECT_NE(std::string(e.what()).find(piece), std::string::npos) << e.what();
    }
  };
  psi::Mask tiny(64, 64, 0);
  tiny.v[32 * 64 + 32] = 1;
  refused(tiny, 1.0, hariharan5(), "a mask of 16 pixels or more");
  refused(scene.mask, 0.0, hariharan5(), "retake time 0 s");
  SequenceParams lsq;
  lsq.steps_rad = {0.0, 1.0, 2.0, 3.0};
  refused(scene.mask, 1.0, lsq, "takes its reference from the first frames");
}

}  // namespace
}  // namespace piezoshift::instrument
