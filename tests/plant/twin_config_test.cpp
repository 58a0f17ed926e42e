// configs/paper.toml is the twin's built-in default, and bad twin values are refused by name.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <unistd.h>

#include "piezoshift/config/project_config.hpp"
#include "piezoshift/core/bounds.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/plant/twin_ranges.hpp"

#include "../support/test_paths.hpp"

namespace piezoshift::io {
namespace {

using config::load_project_config;
using config::ProjectConfig;

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
  } catch (const core::InputError& e) {
    std::filesystem::remove(path);
    return e.what();
  }
  std::filesystem::remove(path);
  ADD_FAILURE() << "no error for:\n" << text;
  return {};
}

TEST(TwinConfig, PaperTomlIsExactlyTheBuiltInTwin) {
  const ProjectConfig c = load_project_config(testing::source_dir() + "/configs/paper.toml");
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

// Values that made the twin allocate without bound (bad_alloc), run without bound or loop
// forever are refused by the reader with the file, line, column and key.
TEST(TwinConfig, ValuesBeyondTheTwinsBoundsAreRefusedWithFileLineAndKey) {
  std::string m = error_for("f.toml", "[twin]\nphysics_rate_Hz = 2e12\n");
  EXPECT_NE(m.find("f.toml:2:19: twin.physics_rate_Hz: value 2000000000000 is not allowed: must "
                   "be in [1, 10000000]"),
            std::string::npos)
      << m;
  m = error_for("g.toml", "[twin.daq]\nsample_time_s = 1e6\n");
  EXPECT_NE(m.find("g.toml:2:17: twin.daq.sample_time_s: value 1000000 is not allowed: must be in "
                   "[1e-05, 1]"),
            std::string::npos)
      << m;
  m = error_for("h.toml", "[twin.amplifier]\noutput_max_V = 5e-324\n");
  EXPECT_NE(m.find("h.toml:2:16: twin.amplifier.output_max_V: value 5e-324 is not allowed: must be "
                   "in [1, 1000]"),
            std::string::npos)
      << m;
  // each value in range, the pair beyond the per-tick physics limit: 1e7 Hz * 0.01 s = 1e5 steps
  m = error_for("i.toml", "[twin]\nphysics_rate_Hz = 1e7\n[twin.daq]\nsample_time_s = 0.01\n");
  EXPECT_NE(m.find("100000 physics steps per control tick is more than the twin's limit of 10000"),
            std::string::npos)
      << m;
}

// Reproducers: settings that loaded and failed later without naming the key are refused at load
// with the file, line and key (tests/plant/twin_ranges_edges_test.cpp tries every key's ends).
TEST(TwinConfig, ValuesThatFailedLaterAreRefusedAtLoadWithTheirKey) {
  std::string m = error_for("j.toml", "[twin.amplifier]\ngain = 5e-324\n");
  EXPECT_NE(m.find("j.toml:2:8: twin.amplifier.gain: value 5e-324 is not allowed: must be in "
                   "[1, 1000]"),
            std::string::npos)
      << m;
  m = error_for("k.toml", "[twin.daq]\nresolution_bits = 2\n");
  EXPECT_NE(m.find("k.toml:2:19: twin.daq.resolution_bits: value 2 is not allowed: must be in "
                   "[12, 32]"),
            std::string::npos)
      << m;
  m = error_for("l.toml", "[twin.interferometer]\nresolution_nm = 1e-320\n");
  EXPECT_NE(m.find("l.toml:2:17: twin.interferometer.resolution_nm"), std::string::npos) << m;
}

// The ranges are one list: the paper's values are inside it, and a struct built in code (as the
// Python bindings do) is checked against the same list, naming the TOML key.
TEST(TwinConfig, TheRangesListCoversTheDefaultsAndChecksStructsBuiltInCode) {
  EXPECT_EQ(plant::twin_ranges_problem(plant::TwinParams{}), "");
  int values = 0;
  plant::TwinParams t;
  plant::visit_twin_values(t, [&](const char*, const char*, auto&, core::Bounds) { ++values; });
  // every key of configs/paper.toml's twin sections but nonlinearity_shape (a name) and
  // in_fringes (a switch), both read apart
  EXPECT_EQ(values, 66);
  t.sgs.offset_V[2] = 200.0;
  EXPECT_EQ(plant::twin_ranges_problem(t), "twin.sgs.offset_V[2] = 200 must be in [-100, 100]");
  EXPECT_NE(plant::twin_params_problem({}, t).find("twin.sgs.offset_V[2]"), std::string::npos);
}

}  // namespace
}  // namespace piezoshift::io
