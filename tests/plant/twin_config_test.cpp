// configs/paper.toml is the twin's built-in default, and bad twin values are refused by name.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <unistd.h>

#include "piezoshift/io/input_error.hpp"
#include "piezoshift/io/project_config.hpp"

namespace piezoshift::io {
namespace {

std::string write_temp(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("piezoshift_twin_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(path) << text;
  return path.string();
}

std::string error_for(const std::string& name, const std::string& text) {
  const std::string path = write_temp(name, text);
  try {
    load_project_config(path);
  } catch (const InputError& e) {
    std::filesystem::remove(path);
    return e.what();
  }
  std::filesystem::remove(path);
  ADD_FAILURE() << "no error for:\n" << text;
  return {};
}

TEST(TwinConfig, PaperTomlIsExactlyTheBuiltInTwin) {
  const ProjectConfig c = load_project_config(PIEZOSHIFT_SOURCE_DIR "/configs/paper.toml");
  EXPECT_TRUE(c.twin == plant::TwinParams{});
  EXPECT_EQ(c.twin.daq.resolution_bits, 16);
  EXPECT_EQ(c.twin.geometry.transmission_matrix[2][2], -0.2980);
  EXPECT_FALSE(c.twin.contact.stiffness_N_per_um.has_value());
}

TEST(TwinConfig, AnyParameterCanBeOverridden) {
  const std::string path = write_temp("ok.toml", R"(
[twin]
physics_rate_Hz = 40000.0
[twin.contact]
stiffness_N_per_um = 50.0
[twin.sgs]
nonlinearity_shape = "wave"
offset_V = [0.01, 0.0, -0.01]
[twin.piezo]
free_stroke_scale = [0.95, 1.0, 1.05]
)");
  const ProjectConfig c = load_project_config(path);
  std::filesystem::remove(path);
  EXPECT_EQ(c.twin.physics_rate_Hz, 40000.0);
  ASSERT_TRUE(c.twin.contact.stiffness_N_per_um.has_value());
  EXPECT_EQ(*c.twin.contact.stiffness_N_per_um, 50.0);
  EXPECT_EQ(c.twin.sgs.nonlinearity_shape, plant::SgsNonlinearityShape::kWave);
  EXPECT_EQ(c.twin.sgs.offset_V[2], -0.01);
  EXPECT_EQ(c.twin.piezo.free_stroke_scale[0], 0.95);
  EXPECT_EQ(c.twin.amplifier.gain, 15.0);  // untouched keys keep the paper's values
}

TEST(TwinConfig, BadValuesAreRefusedByName) {
  EXPECT_NE(error_for("a.toml", "[twin.amplifier]\ngain = -15\n").find("twin.amplifier.gain"),
            std::string::npos);
  EXPECT_NE(error_for("b.toml", "[twin.sgs]\nnonlinearity_shape = \"zigzag\"\n").find("zigzag"),
            std::string::npos);
  EXPECT_NE(error_for("c.toml", "[twin]\nphysics_rate_Hz = 12345.0\n").find("whole number"),
            std::string::npos);
  EXPECT_NE(error_for("d.toml", "[twin.piezo]\nhysteresis_fraction = 0.6\n")
                .find("twin.piezo.hysteresis_fraction"),
            std::string::npos);
  EXPECT_NE(
      error_for("e.toml", "[twin.lab]\ntemperature_period = 900\n").find("temperature_period"),
      std::string::npos);
}

}  // namespace
}  // namespace piezoshift::io
