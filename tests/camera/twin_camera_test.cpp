#include "piezoshift/camera/twin_camera.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include "../runtime/allocation_counter.hpp"
#include "piezoshift/camera/camera_config.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/plant/random.hpp"
#include "piezoshift/psi/simulation.hpp"

namespace piezoshift::camera {
namespace {

constexpr int kSide = 32;

TwinScene scene(std::uint64_t seed = 7) {
  TwinScene s;
  s.fizeau.width_px = kSide;
  s.fizeau.height_px = kSide;
  s.fizeau.pupil_radius_px = 14.0;
  s.mask = psi::disk_mask(kSide, kSide, 14.0);
  plant::Rng rng(3);
  s.surface_nm = psi::make_surface_nm(psi::parse_surface_spec("Z4=60,Z7=20,rough=1"), s.mask, rng);
  s.seed = seed;
  return s;
}

CameraSettings settings(PixelFormat format = PixelFormat::kMono12) {
  CameraSettings c;
  c.width_px = kSide;
  c.height_px = kSide;
  c.format = format;
  c.exposure_s = 1e-3;
  c.readout_s = 4e-3;
  c.buffer_count = 4;
  return c;
}

psi::CameraParams sensor() {
  psi::CameraParams p = CameraConfig{}.sensor;
  p.read_noise_e = 20.0;  // noise large enough that another seed changes every frame
  return p;
}

// Three poses a loop at 2 kHz reports over the exposure starting at t: the plate ramps by
// step_nm, so the frame is blurred as the renderer integrates it.
std::vector<psi::PoseSample> ramp(double t, double base_nm, double step_nm) {
  return {{t, base_nm, 0.0, 0.0},
          {t + 5e-4, base_nm + 0.5 * step_nm, 1.0, -0.5},
          {t + 1e-3, base_nm + step_nm, 2.0, -1.0}};
}

void feed(Camera& cam, const std::vector<psi::PoseSample>& poses) {
  for (const psi::PoseSample& p : poses)
    cam.observe_plate({p.time_s, p.piston_nm, p.theta_x_urad, p.theta_y_urad});
}

// A sequence of five frames, pi/2 apart, each triggered, exposed and polled.
std::vector<std::vector<std::uint16_t>> sequence(TwinCamera& cam, bool poll_each) {
  cam.start();
  std::vector<std::vector<std::uint16_t>> out;
  Frame f;
  for (int k = 0; k < 4; ++k) {
    EXPECT_TRUE(cam.trigger(0.005 * k)) << cam.message();
    feed(cam, ramp(0.005 * k, 79.1 * k, 2.0));
    if (poll_each) {
      EXPECT_EQ(cam.wait(f, 10.0), FrameStatus::kOk) << cam.message();
      out.push_back(f.counts);
    }
  }
  while (out.size() < 4) {
    EXPECT_EQ(cam.wait(f, 10.0), FrameStatus::kOk) << cam.message();
    out.push_back(f.counts);
  }
  cam.stop();
  return out;
}

std::uint64_t splitmix64(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

TEST(TwinCameraTest, SceneIsPsiSimulatesTruthForTheSameSeed) {
  psi::SimulationParams p;
  p.fizeau.width_px = 48;
  p.fizeau.height_px = 40;
  p.fizeau.pupil_radius_px = 18.0;
  p.surface = psi::parse_surface_spec("Z4=30,Z8=-5,rough=0.7");
  p.seed = 11;
  const TwinScene s = make_twin_scene(p.surface, p.fizeau, p.seed);
  // psi simulate's truth, drawn as simulation.cpp does
  const psi::Mask mask = psi::disk_mask(48, 40, 18.0);
  plant::Rng rng(11);
  const psi::Map truth = psi::make_surface_nm(p.surface, mask, rng);
  EXPECT_EQ(s.mask.v, mask.v);
  ASSERT_EQ(s.surface_nm.size(), truth.size());
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (mask.v[i]) {
      ASSERT_EQ(s.surface_nm.v[i], truth.v[i]) << "pixel " << i;
    }
  }
  EXPECT_EQ(s.seed, 11u);
  p.fizeau.wavelength_nm = 10.0;
  EXPECT_THROW(make_twin_scene(p.surface, p.fizeau, 1), core::InputError);
}

TEST(TwinCameraTest, FrameSeedIsSplitmixOfSeedThenFrame) {
  EXPECT_EQ(splitmix64(0), 0xe220a8397b1dcdafULL);  // the published first output for seed 0
  EXPECT_EQ(frame_seed(7, 3), splitmix64(splitmix64(7) ^ 3));
  EXPECT_NE(frame_seed(7, 0), frame_seed(7, 1));
  EXPECT_NE(frame_seed(7, 1), frame_seed(8, 1));
}

TEST(TwinCameraTest, FrameIsRenderFrameOfTheExposuresPosesAndSeed) {
  const TwinScene sc = scene();
  TwinCamera cam(sc, sensor());
  cam.configure(settings());
  cam.start();
  Frame f;
  for (std::uint64_t k = 0; k < 2; ++k) {
    const double t = 0.01 * static_cast<double>(k);
    ASSERT_TRUE(cam.trigger(t)) << cam.message();
    const std::vector<psi::PoseSample> poses = ramp(t, 158.2 * static_cast<double>(k), 3.0);
    cam.observe_plate({t - 5e-4, 999.0, 0.0, 0.0});  // before the trigger: not in the exposure
    feed(cam, poses);
    cam.observe_plate({t + 1.5e-3, 999.0, 0.0, 0.0});  // after it: not either
    ASSERT_EQ(cam.wait(f, 10.0), FrameStatus::kOk) << cam.message();

    psi::CameraParams p = sensor();
    p.bit_depth = 12;
    plant::Rng rng(splitmix64(splitmix64(sc.seed) ^ k));
    const psi::Map expected = psi::render_frame(sc.surface_nm, sc.mask, sc.fizeau, p, poses, rng);
    ASSERT_EQ(f.counts.size(), expected.size());
    for (std::size_t i = 0; i < expected.size(); ++i)
      ASSERT_EQ(f.counts[i], expected.v[i]) << "pixel " << i << " of frame " << k;
    EXPECT_EQ(f.frame_id, k);
    EXPECT_EQ(f.width_px, kSide);
    EXPECT_EQ(f.format, PixelFormat::kMono12);
    EXPECT_DOUBLE_EQ(f.trigger_time_s, t);
    EXPECT_EQ(f.device_timestamp_ns, static_cast<std::int64_t>(k) * 10000000);
    EXPECT_GT(f.system_timestamp_ns, 0);
    // fringes, not a flat field
    const auto [lo, hi] = std::minmax_element(f.counts.begin(), f.counts.end());
    EXPECT_GT(*hi - *lo, 1500);
  }
  cam.stop();
}

TEST(TwinCameraTest, TriggerRefusedUntilExposureAndReadoutAreOver) {
  TwinCamera cam(scene(), sensor());
  cam.configure(settings());
  EXPECT_FALSE(cam.trigger(0.0));
  EXPECT_NE(cam.message().find("not started"), std::string::npos) << cam.message();
  cam.start();
  ASSERT_TRUE(cam.trigger(0.0));
  feed(cam, ramp(0.0, 0.0, 0.0));
  EXPECT_FALSE(cam.trigger(0.004));  // 1 ms exposure + 4 ms readout: not before 5 ms
  EXPECT_NE(cam.message().find("readout"), std::string::npos) << cam.message();
  EXPECT_FALSE(cam.trigger(std::nan("")));
  EXPECT_TRUE(cam.trigger(0.001 + 0.004)) << cam.message();  // exactly at the end
  feed(cam, ramp(0.005, 0.0, 0.0));
  Frame f;
  ASSERT_EQ(cam.wait(f, 10.0), FrameStatus::kOk);
  EXPECT_EQ(f.frame_id, 0u);
  ASSERT_EQ(cam.wait(f, 10.0), FrameStatus::kOk);
  EXPECT_EQ(f.frame_id, 1u);  // the refused triggers took no id
  EXPECT_EQ(cam.poll(f), FrameStatus::kNone);
  cam.stop();
}

TEST(TwinCameraTest, ExposureWithoutAPoseIsAnErrorNotABlankFrame) {
  TwinCamera cam(scene(), sensor());
  cam.configure(settings());
  cam.start();
  ASSERT_TRUE(cam.trigger(0.0));
  cam.observe_plate({0.002, 0.0, 0.0, 0.0});  // the first tick after the trigger is past the end
  Frame f;
  f.counts.assign(4, 7);  // a previous image: not handed back as this frame's
  ASSERT_EQ(cam.wait(f, 10.0), FrameStatus::kError);
  EXPECT_EQ(f.frame_id, 0u);
  EXPECT_TRUE(f.counts.empty());
  EXPECT_NE(cam.message().find("frame 0 saw no plate pose"), std::string::npos) << cam.message();
  // No pose at all before the next trigger: that exposure is an error too, the next one is not.
  ASSERT_TRUE(cam.trigger(0.01));
  ASSERT_TRUE(cam.trigger(0.02));
  feed(cam, ramp(0.02, 0.0, 1.0));
  ASSERT_EQ(cam.wait(f, 10.0), FrameStatus::kError);
  EXPECT_EQ(f.frame_id, 1u);
  ASSERT_EQ(cam.wait(f, 10.0), FrameStatus::kOk) << cam.message();
  EXPECT_EQ(f.frame_id, 2u);
  cam.stop();
}

TEST(TwinCameraTest, MorePosesThanTheBufferHoldsIsAnError) {
  TwinScene sc = scene();
  sc.max_tick_rate_Hz = 2000.0;  // 1 ms exposure: 2 + 2 poses
  TwinCamera cam(sc, sensor());
  cam.configure(settings());
  EXPECT_EQ(cam.pose_capacity(), 4u);
  cam.start();
  ASSERT_TRUE(cam.trigger(0.0));
  for (int k = 0; k <= 10; ++k)
    cam.observe_plate({k * 1e-4, 0.0, 0.0, 0.0});  // 10 kHz
  Frame f;
  ASSERT_EQ(cam.wait(f, 10.0), FrameStatus::kError);
  EXPECT_NE(cam.message().find("more than 4 plate poses"), std::string::npos) << cam.message();
  cam.stop();
}

TEST(TwinCameraTest, SameSeedSameFramesWhateverTheThreadsTiming) {
  TwinCamera a(scene(7), sensor()), b(scene(7), sensor()), c(scene(8), sensor());
  a.configure(settings());
  b.configure(settings());
  c.configure(settings());
  const auto fa = sequence(a, true);
  const auto fb = sequence(b, false);  // all triggered before the first poll
  const auto fc = sequence(c, true);
  ASSERT_EQ(fa.size(), 4u);
  EXPECT_EQ(fa, fb);
  for (std::size_t k = 0; k < fa.size(); ++k)
    EXPECT_NE(fa[k], fc[k]) << "frame " << k;
  EXPECT_NE(fa[0], fa[1]);  // the steps move the fringes
  // a second run of the same camera starts again at frame 0 with the same noise
  EXPECT_EQ(sequence(a, true), fa);
}

TEST(TwinCameraTest, CountsSpanThePixelFormatsBitDepth) {
  psi::CameraParams bright = sensor();
  bright.mean_fill = 0.9;  // 1.9 x the full well at a bright fringe: saturates
  bright.visibility = 1.0;
  for (const auto& [format, top] : {std::pair{PixelFormat::kMono8, 255},
                                    {PixelFormat::kMono12, 4095},
                                    {PixelFormat::kMono16, 65535}}) {
    TwinCamera cam(scene(), bright);
    cam.configure(settings(format));
    cam.start();
    ASSERT_TRUE(cam.trigger(0.0));
    feed(cam, ramp(0.0, 0.0, 0.0));
    Frame f;
    ASSERT_EQ(cam.wait(f, 10.0), FrameStatus::kOk);
    EXPECT_EQ(f.format, format);
    EXPECT_EQ(*std::max_element(f.counts.begin(), f.counts.end()), top) << to_string(format);
    cam.stop();
  }
}

TEST(TwinCameraTest, GainScalesTheCountsAndClipsAtFullScale) {
  auto frame = [](double gain_dB) {
    TwinCamera cam(scene(), sensor());
    CameraSettings s = settings();
    s.gain_dB = gain_dB;
    cam.configure(s);
    cam.start();
    EXPECT_TRUE(cam.trigger(0.0));
    feed(cam, ramp(0.0, 0.0, 0.0));
    Frame f;
    EXPECT_EQ(cam.wait(f, 10.0), FrameStatus::kOk);
    return f.counts;
  };
  const auto unity = frame(0.0), six = frame(6.0);
  ASSERT_EQ(unity.size(), six.size());
  int clipped = 0;
  for (std::size_t p = 0; p < unity.size(); ++p) {
    const double expected = std::min(4095.0, std::round(unity[p] * 1.9952623149688795));
    ASSERT_EQ(six[p], expected) << "pixel " << p;
    clipped += six[p] == 4095;
  }
  EXPECT_GT(clipped, 0);
}

TEST(TwinCameraTest, LoopSideAndPollAllocateNothing) {
  TwinCamera cam(scene(), sensor());
  cam.configure(settings());
  cam.start();
  Frame f;
  f.counts.resize(kSide * kSide);
  long allocations = 0;
  int triggered = 0, delivered = 0;
  for (int k = 0; k < 3; ++k) {
    const double t = 0.005 * k;
    const std::vector<psi::PoseSample> poses = ramp(t, 10.0 * k, 1.0);
    runtime::testing::AllocationCounter counter;
    triggered += cam.trigger(t);
    feed(cam, poses);
    allocations += counter.stop();
    for (int tries = 0; tries < 10000; ++tries) {
      runtime::testing::AllocationCounter poll_counter;
      const FrameStatus status = cam.poll(f);  // the one that delivers the frame included
      allocations += poll_counter.stop();
      if (status != FrameStatus::kNone) {
        delivered += status == FrameStatus::kOk;
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }
  EXPECT_EQ(triggered, 3);
  EXPECT_EQ(delivered, 3);
  EXPECT_EQ(allocations, 0);
  cam.stop();
}

TEST(TwinCameraTest, FullBuffersRefuseTheTriggerUntilAFrameIsPolled) {
  TwinCamera cam(scene(), sensor());
  CameraSettings s = settings();
  s.buffer_count = 2;
  cam.configure(s);
  cam.start();
  for (int k = 0; k < 2; ++k) {
    ASSERT_TRUE(cam.trigger(0.005 * k));
    feed(cam, ramp(0.005 * k, 0.0, 0.0));
  }
  EXPECT_FALSE(cam.trigger(0.01));
  EXPECT_NE(cam.message().find("all 2 buffers"), std::string::npos) << cam.message();
  Frame f;
  ASSERT_EQ(cam.wait(f, 10.0), FrameStatus::kOk);
  EXPECT_TRUE(cam.trigger(0.01)) << cam.message();
  feed(cam, ramp(0.01, 0.0, 0.0));
  ASSERT_EQ(cam.wait(f, 10.0), FrameStatus::kOk);
  ASSERT_EQ(cam.wait(f, 10.0), FrameStatus::kOk);
  EXPECT_EQ(f.frame_id, 2u);
  cam.stop();
}

TEST(TwinCameraTest, ConfigureRefusesAnotherSizeAndValuesOutOfRange) {
  TwinCamera cam(scene(), sensor());
  auto refusal = [&](CameraSettings s) {
    try {
      cam.configure(s);
    } catch (const core::InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  CameraSettings s = settings();
  s.width_px = 64;
  EXPECT_NE(refusal(s).find("width_px x height_px = 64 x 32"), std::string::npos) << refusal(s);
  s = settings();
  // A trigger line is the sim backend's wire (its edges reach trigger()): taken.
  s.trigger = TriggerSource::kLine;
  EXPECT_EQ(refusal(s), "accepted");
  EXPECT_EQ(cam.settings().trigger, TriggerSource::kLine);
  s = settings();
  s.exposure_s = 0.0;
  EXPECT_NE(refusal(s).find("camera.exposure_s"), std::string::npos) << refusal(s);
  EXPECT_THROW(TwinCamera(scene(),
                          [] {
                            psi::CameraParams p = sensor();
                            p.full_well_e = 10.0;
                            return p;
                          }()),
               core::InputError);
  TwinScene wrong = scene();
  wrong.mask = psi::disk_mask(16, 16, 6.0);
  EXPECT_THROW(TwinCamera(wrong, sensor()), core::InputError);
}

}  // namespace
}  // namespace piezoshift::camera
