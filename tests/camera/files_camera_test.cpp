#include "piezoshift/camera/files_camera.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "piezoshift/camera/aravis_camera.hpp"
#include "piezoshift/camera/make_camera.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/plant/random.hpp"
#include "piezoshift/psi/png_image.hpp"
#include "temp_dir_test.hpp"

namespace piezoshift::camera {
namespace {

constexpr int kSide = 24;

CameraSettings settings(PixelFormat format = PixelFormat::kMono12) {
  CameraSettings c;
  c.width_px = kSide;
  c.height_px = kSide;
  c.format = format;
  return c;
}

// What `psi simulate` writes: 12-bit counts of the Fizeau simulation in 16-bit PNG files,
// frame_00.png, frame_01.png, ... (pi/2 apart).
std::vector<psi::Map> simulated_frames(int n) {
  psi::FizeauParams f;
  f.width_px = kSide;
  f.height_px = kSide;
  f.pupil_radius_px = 10.0;
  const psi::Mask mask = psi::disk_mask(kSide, kSide, 10.0);
  plant::Rng rng(5);
  const psi::Map surface = psi::make_surface_nm(psi::parse_surface_spec("Z4=50"), mask, rng);
  std::vector<psi::Map> frames;
  for (int k = 0; k < n; ++k) {
    const psi::PoseSample pose{0.0, 79.1 * k, 0.0, 0.0};
    frames.push_back(psi::render_frame(surface, mask, f, psi::CameraParams{}, {&pose, 1}, rng));
  }
  return frames;
}

class FilesCameraTest : public testing::TempDirTest {
 protected:
  std::string error_of(const std::function<void()>& f) {
    try {
      f();
    } catch (const core::InputError& e) {
      return e.what();
    }
    return "no error";
  }
};

TEST_F(FilesCameraTest, ReplaysTheFilesInNameOrderThenReportsRunningOut) {
  const std::vector<psi::Map> frames = simulated_frames(5);
  for (int k : {3, 0, 4, 1, 2})  // written out of order: the replay is by name
    psi::write_png_gray16(path(fmt::format("frame_{:02}.png", k)), frames[k]);
  write("notes.txt", "not a frame");
  FilesCamera cam(dir_.string());
  ASSERT_EQ(cam.files().size(), 5u);
  cam.configure(settings());
  cam.start();
  Frame f;
  EXPECT_EQ(cam.poll(f), FrameStatus::kNone);  // nothing triggered
  for (int k = 0; k < 5; ++k) {
    ASSERT_TRUE(cam.trigger(0.1 * k));
    ASSERT_EQ(cam.wait(f, 1.0), FrameStatus::kOk) << cam.message();
    EXPECT_EQ(f.frame_id, static_cast<std::uint64_t>(k));
    EXPECT_DOUBLE_EQ(f.trigger_time_s, 0.1 * k);
    EXPECT_EQ(f.format, PixelFormat::kMono12);
    ASSERT_EQ(f.counts.size(), frames[k].size());
    for (std::size_t p = 0; p < f.counts.size(); ++p)
      ASSERT_EQ(f.counts[p], frames[k].v[p]) << "frame " << k << " pixel " << p;
  }
  ASSERT_TRUE(cam.trigger(0.5));
  ASSERT_EQ(cam.wait(f, 1.0), FrameStatus::kError);
  EXPECT_EQ(f.frame_id, 5u);
  EXPECT_TRUE(f.counts.empty());  // not frame 4's image again
  EXPECT_NE(cam.message().find("frame 5 was triggered but the directory holds only 5 PNG"),
            std::string::npos)
      << cam.message();
  EXPECT_NE(cam.message().find("frame_04.png"), std::string::npos) << cam.message();
  // start() replays from the first file again
  cam.start();
  ASSERT_TRUE(cam.trigger(0.0));
  ASSERT_EQ(cam.poll(f), FrameStatus::kOk);
  EXPECT_EQ(f.counts[static_cast<std::size_t>(kSide) * kSide / 2], frames[0].v[kSide * kSide / 2]);
  cam.stop();
  EXPECT_FALSE(cam.trigger(1.0));
  EXPECT_NE(cam.message().find("not started"), std::string::npos) << cam.message();
}

TEST_F(FilesCameraTest, MissingOrEmptyDirectoriesAreRefusedByName) {
  const std::string missing = path("nowhere");
  EXPECT_NE(error_of([&] { FilesCamera c(missing); }).find(missing + ": not a directory"),
            std::string::npos);
  write("readme.txt", "no frames here");
  EXPECT_NE(error_of([&] { FilesCamera c(dir_.string()); }).find("holds no PNG file"),
            std::string::npos);
  for (int k = 0; k < 65; ++k)
    write(fmt::format("f{:03}.png", k), "");
  EXPECT_NE(error_of([&] { FilesCamera c(dir_.string()); }).find("65 PNG files, at most 64"),
            std::string::npos);
}

// A FIFO, a link to a device or a link loop among the *.png files was skipped and every later
// frame shifted one step: each is refused by name before anything is decoded. A link to a
// regular PNG is a frame.
TEST_F(FilesCameraTest, APngThatIsNotARegularFileIsRefusedByName) {
  const std::vector<psi::Map> frames = simulated_frames(3);
  for (int k = 0; k < 3; ++k)
    psi::write_png_gray16(path(fmt::format("frame_{:02}.png", k)), frames[k]);
  std::filesystem::create_symlink(path("frame_02.png"), path("frame_03.png"));
  {
    FilesCamera cam(dir_.string());
    ASSERT_EQ(cam.files().size(), 4u);
    cam.configure(settings());
  }
  const std::string prefix = "camera files:" + dir_.string() + ": frame_01b.png: ";
  const std::string suffix = "; every *.png must be a regular file";
  ASSERT_EQ(::mkfifo(path("frame_01b.png").c_str(), 0600), 0);
  EXPECT_EQ(error_of([&] { FilesCamera c(dir_.string()); }), prefix + "a FIFO (pipe)" + suffix);
  std::filesystem::remove(path("frame_01b.png"));
  std::filesystem::create_symlink("/dev/zero", path("frame_01b.png"));
  EXPECT_EQ(error_of([&] { FilesCamera c(dir_.string()); }),
            prefix + "a link to a device" + suffix);
  std::filesystem::remove(path("frame_01b.png"));
  std::filesystem::create_symlink(path("frame_01b.png"), path("frame_01b.png"));
  EXPECT_EQ(error_of([&] { FilesCamera c(dir_.string()); }),
            prefix + "a link that does not lead to a file (" +
                std::make_error_code(std::errc::too_many_symbolic_link_levels).message() + ")" +
                suffix);
  std::filesystem::remove(path("frame_01b.png"));
  std::filesystem::create_directory(path("frame_01b.png"));
  EXPECT_EQ(error_of([&] { FilesCamera c(dir_.string()); }), prefix + "a directory" + suffix);
}

TEST_F(FilesCameraTest, SizeOrBitDepthOtherThanTheSettingsIsRefusedNamingTheFile) {
  std::vector<psi::Map> frames = simulated_frames(2);
  psi::write_png_gray16(path("frame_00.png"), frames[0]);
  psi::write_png_gray16(path("frame_01.png"), psi::Map(kSide + 1, kSide, 100.0));
  FilesCamera cam(dir_.string());
  const std::string size = error_of([&] { cam.configure(settings()); });
  EXPECT_NE(size.find("frame_01.png: 25 x 24 pixels, but camera.width_px x height_px is 24 x 24"),
            std::string::npos)
      << size;
  EXPECT_THROW(cam.start(), core::InputError);  // not configured

  psi::write_png_gray16(path("frame_01.png"), frames[1]);
  const std::string depth = error_of([&] { cam.configure(settings(PixelFormat::kMono8)); });
  EXPECT_NE(depth.find("frame_00.png: a 16-bit PNG, but camera.pixel_format is Mono8"),
            std::string::npos)
      << depth;

  frames[1].v[kSide + 2] = 5000.0;  // not a 12-bit count
  psi::write_png_gray16(path("frame_01.png"), frames[1]);
  const std::string range = error_of([&] { cam.configure(settings()); });
  EXPECT_NE(range.find("frame_01.png: pixel (2, 1) = 5000 counts, above 4095"), std::string::npos)
      << range;
  cam.configure(settings(PixelFormat::kMono16));  // a 16-bit camera takes it
}

TEST_F(FilesCameraTest, FactoryBuildsFilesAndRefusesUnknownSpecsAndAravis) {
  psi::write_png_gray16(path("frame_00.png"), simulated_frames(1)[0]);
  CameraConfig config;
  config.settings = settings();
  const auto cam = make_camera("files:" + dir_.string(), config);
  EXPECT_EQ(cam->name(), "files:" + dir_.string());
  EXPECT_EQ(cam->settings().width_px, kSide);  // configured by the factory

  config.settings.width_px = 32;  // configure() runs in the factory: the size is refused there
  EXPECT_NE(error_of([&] {
              make_camera("files:" + dir_.string(), config);
            }).find("frame_00.png: 24 x 24 pixels"),
            std::string::npos);
  EXPECT_EQ(error_of([&] { make_camera("webcam", config); }),
            "camera 'webcam': not a camera (expected twin, files:DIR or aravis:ID)");
  // aravis: goes to the Aravis backend: where it is built in, the fake camera refuses the
  // default Mono12 (it offers Mono8 and Mono16 only); elsewhere the hook refuses it.
  const std::string aravis_error = error_of([&] { make_camera("aravis:Fake_1", config); });
  if (aravis_available())
    EXPECT_NE(aravis_error.find("Mono12"), std::string::npos) << aravis_error;
  else
    EXPECT_NE(aravis_error.find("built without Aravis"), std::string::npos) << aravis_error;
  EXPECT_NE(error_of([&] { make_camera("twin", config); }).find("camera twin: no simulated"),
            std::string::npos);
  EXPECT_NE(error_of([&] { make_camera("files:", config); }).find("no directory"),
            std::string::npos);
  config.settings.exposure_s = 5.0;
  EXPECT_NE(error_of([&] {
              make_camera("files:" + dir_.string(), config);
            }).find("camera.exposure_s = 5"),
            std::string::npos);
}

TEST(MakeCameraTest, TwinFromTheFactoryTakesTheConfigsSensor) {
  TwinScene scene;
  scene.fizeau.width_px = 16;
  scene.fizeau.height_px = 16;
  scene.fizeau.pupil_radius_px = 6.0;
  scene.mask = psi::disk_mask(16, 16, 6.0);
  scene.surface_nm = psi::Map(16, 16, 0.0);
  CameraConfig config;
  config.settings.width_px = 16;
  config.settings.height_px = 16;
  config.settings.format = PixelFormat::kMono8;
  config.sensor.read_noise_e = 0.0;
  config.sensor.shot_noise = false;
  config.sensor.mean_fill = 0.5;
  config.sensor.visibility = 0.5;
  const auto cam = make_camera("twin", config, &scene);
  EXPECT_EQ(cam->name(), "twin");
  cam->start();
  ASSERT_TRUE(cam->trigger(0.0));
  cam->observe_plate({0.0, 0.0, 0.0, 0.0});
  cam->observe_plate({0.001, 0.0, 0.0, 0.0});
  Frame f;
  ASSERT_EQ(cam->wait(f, 10.0), FrameStatus::kOk) << cam->message();
  // A flat surface with the plate at 0: cos 0 = 1 in the pupil, e = 0.5 (1 + 0.5) full well;
  // outside it the background 0.5 full well. 8 bits: round(0.75 x 255) and round(0.5 x 255).
  EXPECT_EQ(f.counts[8 * 16 + 8], 191);
  EXPECT_EQ(f.counts[0], 128);
  cam->stop();
}

}  // namespace
}  // namespace piezoshift::camera
