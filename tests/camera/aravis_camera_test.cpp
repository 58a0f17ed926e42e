// aravis:ID against Aravis's in-process fake camera (Fake_1); the GigE Vision path is
// aravis_gv_camera_test.cpp. No test needs a real camera.
#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include "piezoshift/camera/aravis_camera.hpp"
#include "piezoshift/camera/aravis_fake_fill.hpp"
#include "piezoshift/core/input_error.hpp"

namespace piezoshift::camera {
namespace {

::testing::AssertionResult has(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos)
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "'" << text << "' lacks '" << part << "'";
}

#define SKIP_WITHOUT_ARAVIS() \
  if (!aravis_available())    \
  GTEST_SKIP() << "built without Aravis (libaravis-dev): aravis: cannot be tested"

CameraSettings fake_settings(PixelFormat format) {
  CameraSettings s;
  s.width_px = 256;
  s.height_px = 256;
  s.format = format;
  s.exposure_s = 10e-3;  // the fake's ramp is unscaled at 10 ms and gain 0
  s.gain_dB = 0.0;
  s.trigger = TriggerSource::kSoftware;
  s.buffer_count = 8;
  return s;
}

//! Triggers one frame at loop time t and waits for it.
FrameStatus take(Camera& camera, double t, Frame& frame) {
  if (!camera.trigger(t))
    return FrameStatus::kError;
  return camera.wait(frame, 2.0);
}

std::string refusal(Camera& camera, const CameraSettings& settings) {
  try {
    camera.configure(settings);
  } catch (const core::InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

// The fake camera's own diagonal ramp (arvfakecamera.c) at 10 ms and gain 0, for device frame id.
std::uint16_t fake_ramp(PixelFormat format, std::uint64_t x, std::uint64_t y, std::uint64_t id) {
  if (format == PixelFormat::kMono8)
    return static_cast<std::uint16_t>((x + id + y) % 255);
  return static_cast<std::uint16_t>((256 * x + 256 * id + 256 * y) % 65535);
}

void acquires_the_fake_ramp(PixelFormat format) {
  auto camera = make_aravis_camera("Fake_1");
  camera->configure(fake_settings(format));
  EXPECT_EQ(camera->settings().width_px, 256);
  EXPECT_NEAR(camera->settings().exposure_s, 10e-3, 1e-9);
  camera->start();
  Frame frame;
  std::uint64_t first_id = 0;
  std::int64_t last_system_ns = 0;
  for (int i = 0; i < 8; ++i) {
    ASSERT_EQ(take(*camera, 0.5 * i, frame), FrameStatus::kOk) << i << ": " << camera->message();
    if (i == 0)
      first_id = frame.frame_id;
    EXPECT_EQ(frame.frame_id, first_id + i);
    EXPECT_EQ(frame.width_px, 256);
    EXPECT_EQ(frame.height_px, 256);
    EXPECT_EQ(frame.format, format);
    ASSERT_EQ(frame.counts.size(), 256u * 256u);
    EXPECT_EQ(frame.trigger_time_s, 0.5 * i);
    EXPECT_GT(frame.device_timestamp_ns, 0);
    EXPECT_GE(frame.system_timestamp_ns, last_system_ns);
    last_system_ns = frame.system_timestamp_ns;
    int wrong = 0;
    for (std::uint64_t y = 0; y < 256; ++y)
      for (std::uint64_t x = 0; x < 256; ++x)
        wrong += frame.counts[y * 256 + x] != fake_ramp(format, x, y, frame.frame_id);
    EXPECT_EQ(wrong, 0) << "frame " << frame.frame_id;
  }
  EXPECT_EQ(camera->poll(frame), FrameStatus::kNone);  // one frame per trigger, no extra
  EXPECT_EQ(camera->lost_frames(), 0u);
  camera->stop();
}

TEST(AravisFakeCamera, Mono8SoftwareTriggeredFramesHoldTheFakesRamp) {
  SKIP_WITHOUT_ARAVIS();
  acquires_the_fake_ramp(PixelFormat::kMono8);
}

TEST(AravisFakeCamera, Mono16SoftwareTriggeredFramesHoldTheFakesRamp) {
  SKIP_WITHOUT_ARAVIS();
  acquires_the_fake_ramp(PixelFormat::kMono16);
}

TEST(AravisFakeCamera, FrameIdsRunOnAcrossTheDevices16BitWrap) {
  SKIP_WITHOUT_ARAVIS();
  // The fake's ids start at 65401 and wrap 65535 -> 1 as GigE Vision 1.x block ids do.
  auto camera = make_aravis_camera("Fake_1");
  CameraSettings s = fake_settings(PixelFormat::kMono8);
  s.width_px = s.height_px = 64;
  camera->configure(s);
  camera->start();
  Frame frame;
  ASSERT_EQ(take(*camera, 0.0, frame), FrameStatus::kOk) << camera->message();
  const std::uint64_t first = frame.frame_id;
  EXPECT_EQ(first, 65401u);
  for (int i = 1; i < 160; ++i) {
    ASSERT_EQ(take(*camera, i, frame), FrameStatus::kOk) << i << ": " << camera->message();
    ASSERT_EQ(frame.frame_id, first + i);
  }
  EXPECT_EQ(camera->lost_frames(), 0u);
}

TEST(AravisFakeCamera, RefusesAPixelFormatTheDeviceDoesNotList) {
  SKIP_WITHOUT_ARAVIS();
  auto camera = make_aravis_camera("Fake_1");
  const std::string why = refusal(*camera, fake_settings(PixelFormat::kMono12));
  EXPECT_TRUE(has(why, "aravis:Fake_1: PixelFormat: Mono12 is not offered by the device"));
  EXPECT_TRUE(has(why, "Mono8"));
  EXPECT_TRUE(has(why, "Mono16"));
  EXPECT_EQ(camera->message(), why);
}

TEST(AravisFakeCamera, RefusesASizeOutsideTheSensor) {
  SKIP_WITHOUT_ARAVIS();
  auto camera = make_aravis_camera("Fake_1");
  CameraSettings s = fake_settings(PixelFormat::kMono8);
  s.width_px = 100000;
  const std::string why = refusal(*camera, s);
  EXPECT_TRUE(has(why, "aravis:Fake_1: Width: 100000 px is outside the device's"));
}

TEST(AravisCamera, RefusesAMissingCameraNamingIt) {
  SKIP_WITHOUT_ARAVIS();
  auto camera = make_aravis_camera("PZ-NoSuchCamera");
  const std::string why = refusal(*camera, fake_settings(PixelFormat::kMono8));
  EXPECT_TRUE(has(why, "aravis:PZ-NoSuchCamera: device: cannot open 'PZ-NoSuchCamera'"));
  EXPECT_TRUE(has(why, "cameras Aravis sees:"));
}

TEST(AravisFakeCamera, TriggerBeforeStartIsRefusedAndStopIsSafeTwice) {
  SKIP_WITHOUT_ARAVIS();
  auto camera = make_aravis_camera("Fake_1");
  camera->configure(fake_settings(PixelFormat::kMono8));
  EXPECT_FALSE(camera->trigger(0.0));
  EXPECT_EQ(camera->message(), "aravis:Fake_1: trigger() before start()");
  camera->start();
  camera->stop();
  camera->stop();
  EXPECT_FALSE(camera->trigger(0.0));
  Frame frame;
  EXPECT_EQ(camera->poll(frame), FrameStatus::kNone);
}

TEST(AravisFakeCamera, ALineTriggerTakesFramesWithoutTrigger) {
  SKIP_WITHOUT_ARAVIS();
  // The in-process fake camera stands for a line pulsed at its trigger frequency (25 Hz).
  auto camera = make_aravis_camera("Fake_1");
  CameraSettings s = fake_settings(PixelFormat::kMono8);
  s.trigger = TriggerSource::kLine;
  camera->configure(s);
  camera->start();
  Frame frame;
  std::uint64_t first_id = 0;
  for (int i = 0; i < 3; ++i) {
    ASSERT_EQ(camera->wait(frame, 1.0), FrameStatus::kOk) << camera->message();
    if (i == 0)
      first_id = frame.frame_id;
    EXPECT_EQ(frame.frame_id, first_id + i);
    EXPECT_TRUE(std::isnan(frame.trigger_time_s));  // no trigger() recorded for it
  }
  EXPECT_EQ(camera->lost_frames(), 0u);
}

TEST(AravisFakeCamera, RefusesALineTheDeviceDoesNotHave) {
  SKIP_WITHOUT_ARAVIS();
  auto camera = make_aravis_camera("Fake_1@Line1");
  EXPECT_EQ(camera->name(), "aravis:Fake_1@Line1");
  CameraSettings s = fake_settings(PixelFormat::kMono8);
  s.trigger = TriggerSource::kLine;
  EXPECT_TRUE(has(refusal(*camera, s),
                  "aravis:Fake_1@Line1: TriggerSource: Line1 is not offered "
                  "by the device (it offers Line0, Software)"));
}

TEST(AravisFakeCamera, AFullRingReportsEachLostFrameWithItsId) {
  SKIP_WITHOUT_ARAVIS();
  auto camera = make_aravis_camera("Fake_1");
  CameraSettings s = fake_settings(PixelFormat::kMono8);
  s.buffer_count = 2;  // two frame slots: the third unpolled frame has nowhere to go
  camera->configure(s);
  camera->start();
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(camera->trigger(i));
    std::this_thread::sleep_for(std::chrono::milliseconds(30));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  Frame frame;
  std::vector<FrameStatus> statuses;
  std::vector<std::uint64_t> ids;
  for (FrameStatus st; (st = camera->poll(frame)) != FrameStatus::kNone;) {
    statuses.push_back(st);
    ids.push_back(frame.frame_id);
  }
  const std::vector<FrameStatus> expected = {FrameStatus::kOk, FrameStatus::kOk, FrameStatus::kLost,
                                             FrameStatus::kLost, FrameStatus::kLost};
  ASSERT_EQ(statuses, expected);
  for (std::size_t i = 1; i < ids.size(); ++i)
    EXPECT_EQ(ids[i], ids[0] + i);
  EXPECT_EQ(camera->lost_frames(), 3u);
  EXPECT_TRUE(has(camera->message(), "ring full"));
}

// A fringe pattern per frame index, as `measure` hands the twin's frames to the fake camera.
std::uint16_t fringe(std::uint64_t index, int x, int y, int max_count) {
  const double phase = 2.0 * M_PI * (x + 0.5 * y) / 37.0 + index * M_PI / 2.0;
  return static_cast<std::uint16_t>(std::lround(0.5 * max_count * (1.0 + 0.9 * std::cos(phase))));
}

TEST(AravisFakeCamera, AFakeFillArrivesPixelForPixel) {
  SKIP_WITHOUT_ARAVIS();
  auto camera = make_aravis_camera("Fake_1");
  camera->configure(fake_settings(PixelFormat::kMono16));
  std::vector<std::uint64_t> indices;
  fake_fill_with(*camera, [&](const FakeFillFrame& f, std::span<std::uint16_t> counts) {
    indices.push_back(f.index);
    EXPECT_EQ(f.format, PixelFormat::kMono16);
    for (int y = 0; y < f.height_px; ++y)
      for (int x = 0; x < f.width_px; ++x)
        counts[static_cast<std::size_t>(y) * f.width_px + x] = fringe(f.index, x, y, 65535);
  });
  camera->start();
  Frame frame;
  for (std::uint64_t k = 0; k < 5; ++k) {
    ASSERT_EQ(take(*camera, 0.1 * k, frame), FrameStatus::kOk) << camera->message();
    int wrong = 0;
    for (int y = 0; y < 256; ++y)
      for (int x = 0; x < 256; ++x)
        wrong += frame.counts[static_cast<std::size_t>(y) * 256 + x] != fringe(k, x, y, 65535);
    EXPECT_EQ(wrong, 0) << "frame " << k;
  }
  camera->stop();
  EXPECT_EQ(indices, (std::vector<std::uint64_t>{0, 1, 2, 3, 4}));
}

TEST(AravisFakeCamera, AFakeFillSaturatesAtTheFormatsRange) {
  SKIP_WITHOUT_ARAVIS();
  auto camera = make_aravis_camera("Fake_1");
  camera->configure(fake_settings(PixelFormat::kMono8));
  fake_fill_with(*camera, [](const FakeFillFrame&, std::span<std::uint16_t> counts) {
    for (std::size_t i = 0; i < counts.size(); ++i)
      counts[i] = static_cast<std::uint16_t>(i % 512);  // half of them above 255
  });
  camera->start();
  Frame frame;
  ASSERT_EQ(take(*camera, 0.0, frame), FrameStatus::kOk) << camera->message();
  EXPECT_EQ(frame.counts[100], 100);
  EXPECT_EQ(frame.counts[255], 255);
  EXPECT_EQ(frame.counts[256], 255);
  EXPECT_EQ(frame.counts[511], 255);
  EXPECT_EQ(frame.counts[512], 0);
}

TEST(AravisFakeCamera, AFakeFillNeedsTheFakeCameraConfigured) {
  SKIP_WITHOUT_ARAVIS();
  auto camera = make_aravis_camera("Fake_1");
  try {
    fake_fill_with(*camera, [](const FakeFillFrame&, std::span<std::uint16_t>) {});
    FAIL() << "accepted before configure()";
  } catch (const core::InputError& e) {
    EXPECT_TRUE(has(e.what(), "aravis:Fake_1: fake fill: needs the in-process fake camera"));
  }
}

}  // namespace
}  // namespace piezoshift::camera
