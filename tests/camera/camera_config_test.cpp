#include "piezoshift/camera/camera_config.hpp"
#include "piezoshift/camera/twin_camera.hpp"

#include <gtest/gtest.h>

#include <string>

#include "piezoshift/camera/instrument_config.hpp"
#include "piezoshift/core/input_error.hpp"
#include "temp_dir_test.hpp"
#include "test_paths.hpp"

namespace piezoshift::camera {
namespace {

CameraConfig read(const std::string& toml) {
  const io::ConfigFile file = io::ConfigFile::parse(toml, "test.toml");
  CameraConfig c;
  read_camera_section(file, c);
  file.reject_unknown();
  return c;
}

std::string refusal(const std::string& toml) {
  try {
    read(toml);
  } catch (const core::InputError& e) {
    return e.what();
  }
  return "accepted";
}

TEST(CameraConfigTest, DefaultsAreTheBlackflySImx273ThroughARegionOfInterest) {
  const CameraConfig c = read("");
  EXPECT_EQ(c.settings.width_px, 256);
  EXPECT_EQ(c.settings.height_px, 256);
  EXPECT_EQ(c.settings.format, PixelFormat::kMono12);
  EXPECT_EQ(c.settings.exposure_s, 1e-3);
  EXPECT_EQ(c.settings.gain_dB, 0.0);
  EXPECT_EQ(c.settings.trigger, TriggerSource::kSoftware);
  EXPECT_DOUBLE_EQ(c.settings.readout_s, 1.0 / 78.0);
  EXPECT_EQ(c.settings.buffer_count, 16);
  EXPECT_EQ(c.sensor.full_well_e, 10500.0);
  EXPECT_EQ(c.sensor.read_noise_e, 2.3);
  EXPECT_EQ(c.sensor.mean_fill, 0.45);
  EXPECT_EQ(c.sensor.visibility, 0.9);
  EXPECT_EQ(c.sensor.bit_depth, 12);
  EXPECT_EQ(camera_config_problem(c), "");
  EXPECT_NEAR(max_frame_rate_Hz(c.settings), 1.0 / (1e-3 + 1.0 / 78.0), 1e-9);  // 72.4 Hz
}

TEST(CameraConfigTest, EveryKeyIsReadAndTheSensorFollowsTheSettings) {
  const CameraConfig c = read(
      "[camera]\nwidth_px = 640\nheight_px = 480\npixel_format = \"Mono8\"\nexposure_s = 2e-3\n"
      "gain_dB = 6.0\ntrigger = \"line\"\nreadout_s = 0.005\nbuffer_count = 8\n"
      "full_well_e = 20000.0\nread_noise_e = 7.5\nmean_fill = 0.3\nvisibility = 0.8\n"
      "shot_noise = false\n");
  EXPECT_EQ(c.settings.width_px, 640);
  EXPECT_EQ(c.settings.height_px, 480);
  EXPECT_EQ(c.settings.format, PixelFormat::kMono8);
  EXPECT_EQ(c.settings.exposure_s, 2e-3);
  EXPECT_EQ(c.settings.gain_dB, 6.0);
  EXPECT_EQ(c.settings.trigger, TriggerSource::kLine);
  EXPECT_EQ(c.settings.readout_s, 0.005);
  EXPECT_EQ(c.settings.buffer_count, 8);
  EXPECT_EQ(c.sensor.full_well_e, 20000.0);
  EXPECT_EQ(c.sensor.read_noise_e, 7.5);
  EXPECT_EQ(c.sensor.mean_fill, 0.3);
  EXPECT_EQ(c.sensor.visibility, 0.8);
  EXPECT_FALSE(c.sensor.shot_noise);
  EXPECT_EQ(c.sensor.bit_depth, 8);      // from Mono8
  EXPECT_EQ(c.sensor.exposure_s, 2e-3);  // from the settings
  EXPECT_EQ(sensor_params(c).bit_depth, 8);
}

TEST(CameraConfigTest, ValuesOutOfRangeAreRefusedNamingTheKey) {
  EXPECT_NE(refusal("[camera]\nexposure_s = 2.0\n").find("camera.exposure_s"), std::string::npos)
      << refusal("[camera]\nexposure_s = 2.0\n");
  EXPECT_NE(refusal("[camera]\nexposure_s = 0.0\n").find("camera.exposure_s"), std::string::npos);
  EXPECT_NE(refusal("[camera]\nwidth_px = 4\n").find("camera.width_px"), std::string::npos);
  EXPECT_NE(refusal("[camera]\nheight_px = 4096\n").find("camera.height_px"), std::string::npos);
  EXPECT_NE(refusal("[camera]\nbuffer_count = 0\n").find("camera.buffer_count"), std::string::npos);
  EXPECT_NE(refusal("[camera]\ngain_dB = -1.0\n").find("camera.gain_dB"), std::string::npos);
  EXPECT_NE(refusal("[camera]\nmean_fill = 1.0\n").find("camera.mean_fill"), std::string::npos);
  EXPECT_NE(refusal("[camera]\nfull_well_e = 50.0\n").find("camera.full_well_e"),
            std::string::npos);
  EXPECT_NE(refusal("[camera]\nread_noise_e = nan\n").find("camera.read_noise_e"),
            std::string::npos);
  EXPECT_EQ(refusal("[camera]\npixel_format = \"Mono10\"\n"),
            "test.toml: camera.pixel_format: 'Mono10' is not one of Mono8, Mono12, Mono16");
  EXPECT_EQ(refusal("[camera]\ntrigger = \"hardware\"\n"),
            "test.toml: camera.trigger: 'hardware' is not one of software, line");
  EXPECT_NE(refusal("[camera]\nexposure_ms = 1.0\n").find("exposure_ms"), std::string::npos);
  EXPECT_NE(refusal("[camera]\nwidth_px = 1.5\n").find("camera.width_px"), std::string::npos);
}

TEST(CameraConfigTest, EveryBoundOfTheListPassesPsisOwnChecks) {
  // The one list must never accept what the Fizeau simulation refuses: each value at either end
  // of its range (the open ends a hair inside) passes psi::camera_problem and the size check.
  for (int end = 0; end < 2; ++end) {
    CameraConfig c;
    visit_camera_values(c, [&](const char*, const char*, auto& value, core::Bounds b) {
      double v = end == 0 ? b.lo : b.hi;
      if (end == 0 && b.lo_open)
        v = b.lo + 1e-9;
      if (end == 1 && b.hi_open)
        v = b.hi - 1e-9;
      value = static_cast<std::remove_reference_t<decltype(value)>>(v);
    });
    EXPECT_EQ(camera_config_problem(c), "") << "end " << end;
    EXPECT_EQ(psi::camera_problem(sensor_params(c)), "") << "end " << end;
    // the optics a measurement renders with: the size and the pupil's radius on the plate
    EXPECT_EQ(psi::fizeau_problem(measurement_optics(c.settings, c.pupil_radius_m, 632.8)), "")
        << "end " << end;
  }
}

class InstrumentConfigTest : public testing::TempDirTest {};

TEST_F(InstrumentConfigTest, TheWholeFileWithCameraAndSafetyAndUnknownKeysRefused) {
  const std::string ok = write("ok.toml",
                               "[safety]\noutput_max_V = 8.0\n[camera]\nexposure_s = 5e-4\n"
                               "[twin.daq]\nsample_time_s = 0.001\n");
  const InstrumentConfig c = load_instrument_config(ok);
  EXPECT_EQ(c.camera.settings.exposure_s, 5e-4);
  EXPECT_EQ(c.installation.safety.output_max_V, 8.0);
  EXPECT_EQ(c.installation.project.twin.daq.sample_time_s, 0.001);
  const InstrumentConfig paper =
      load_instrument_config(piezoshift::testing::source_dir() + "/configs/paper.toml");
  EXPECT_EQ(paper.camera.settings.width_px, 256);

  const std::string bad = write("bad.toml", "[camera]\nexposure_s = 1e-3\ncolour = true\n");
  try {
    load_instrument_config(bad);
    FAIL() << "accepted an unknown key";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("camera.colour"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("bad.toml"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace piezoshift::camera
