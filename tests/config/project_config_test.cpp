#include "piezoshift/config/project_config.hpp"

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "piezoshift/core/input_error.hpp"

#include "../support/temp_dir_test.hpp"
#include "../support/test_paths.hpp"

namespace piezoshift::io {
namespace {

using config::load_project_config;
using config::ProjectConfig;
using config::read_design_sections;

class ProjectConfigTest : public piezoshift::testing::TempDirTest {
 protected:
  std::string write(const std::string& text) { return TempDirTest::write("config.toml", text); }
  // Loads text that must fail; returns the message, which must name the file.
  std::string error_for(const std::string& text) {
    const std::string path = write(text);
    try {
      load_project_config(path);
    } catch (const core::InputError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(path), std::string::npos) << m;
      return m;
    }
    ADD_FAILURE() << "no core::InputError for:\n" << text;
    return "";
  }
};

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST_F(ProjectConfigTest, PaperTomlGivesExactlyTheDefaults) {
  const ProjectConfig c = load_project_config(testing::source_dir() + "/configs/paper.toml");
  EXPECT_TRUE(c.design == design::DesignInputs{});
  // Spot checks, in case operator== were ever wrong.
  EXPECT_EQ(c.design.actuator.stiffness_N_per_um, 70.0);
  EXPECT_EQ(c.design.material.allowable_stress_Pa, 355e6);
  EXPECT_EQ(c.design.hinge.link_length_m, 18e-3);
  EXPECT_EQ(c.design.mechanism.moving_mass_kg, 0.05075);
}

// The what-if twins docs/compare.md measures change exactly the one thing they name.
TEST_F(ProjectConfigTest, WhatIfConfigsChangeOnlyWhatTheyName) {
  const ProjectConfig equal =
      load_project_config(testing::source_dir() + "/configs/what-if/equal-legs.toml");
  plant::TwinParams expected;
  EXPECT_NE(expected.piezo.free_stroke_scale[1], 1.0);  // the default's short leg
  expected.piezo.free_stroke_scale = {1.0, 1.0, 1.0};
  EXPECT_TRUE(equal.twin == expected);
  EXPECT_TRUE(equal.design == design::DesignInputs{});

  const ProjectConfig still =
      load_project_config(testing::source_dir() + "/configs/what-if/no-excitation-drift.toml");
  expected = plant::TwinParams{};
  EXPECT_GT(expected.sgs.excitation_drift_ppm_rms, 0.0);
  expected.sgs.excitation_drift_ppm_rms = 0.0;
  EXPECT_TRUE(still.twin == expected);
  EXPECT_TRUE(still.design == design::DesignInputs{});
}

TEST_F(ProjectConfigTest, EmptyFileGivesTheDefaults) {
  EXPECT_TRUE(load_project_config(write("")).design == design::DesignInputs{});
}

TEST_F(ProjectConfigTest, MissingKeysKeepTheirDefaults) {
  const ProjectConfig c = load_project_config(
      write("[hinge]\nthickness_m = 1.5e-3\n[material]\nelastic_modulus_Pa = 70e9\n"
            "[actuator]\nnominal_stroke_um = 20\n[mechanism]\nmoving_mass_kg = 0.02\n"));
  design::DesignInputs expected;
  expected.hinge.thickness_m = 1.5e-3;
  expected.material.elastic_modulus_Pa = 70e9;
  expected.actuator.nominal_stroke_um = 20.0;
  expected.mechanism.moving_mass_kg = 0.02;
  EXPECT_TRUE(c.design == expected);
}

TEST_F(ProjectConfigTest, UnknownKeyOrSection) {
  std::string m = error_for("[hinge]\nthicknes_m = 2e-3\n");
  EXPECT_TRUE(contains(m, "hinge.thicknes_m: unknown key")) << m;
  m = error_for("[hinges]\nthickness_m = 2e-3\n");
  EXPECT_TRUE(contains(m, "hinges: unknown section")) << m;
  m = error_for("stiffness_N_per_um = 70\n");  // outside any section
  EXPECT_TRUE(contains(m, "stiffness_N_per_um: unknown key")) << m;
}

TEST_F(ProjectConfigTest, WrongTypeNegativeZeroNan) {
  std::string m = error_for("[actuator]\nstiffness_N_per_um = \"70\"\n");
  EXPECT_TRUE(contains(m, "actuator.stiffness_N_per_um: expected a number")) << m;
  m = error_for("[material]\nelastic_modulus_Pa = -2.1e11\n");
  EXPECT_TRUE(
      contains(m,
               "material.elastic_modulus_Pa: value -210000000000 is not allowed: must be in (0, "
               "10000000000000]"))
      << m;
  m = error_for("[hinge]\nwidth_m = 0\n");
  EXPECT_TRUE(contains(m, "hinge.width_m: value 0 is not allowed: must be in (0, 1]")) << m;
  m = error_for("[mechanism]\nmoving_mass_kg = nan\n");
  EXPECT_TRUE(contains(m, "mechanism.moving_mass_kg: value nan")) << m;
  m = error_for("[actuator]\nnominal_stroke_um = inf\n");
  EXPECT_TRUE(contains(m, "actuator.nominal_stroke_um")) << m;
}

TEST_F(ProjectConfigTest, PoissonRatioMustBeBetweenZeroAndOneHalf) {
  for (const char* v : {"0.5", "0", "-0.1", "0.7"}) {
    const std::string m = error_for(std::string("[material]\npoisson_ratio = ") + v + "\n");
    EXPECT_TRUE(contains(m, "material.poisson_ratio")) << m;
    EXPECT_TRUE(contains(m, "in (0, 0.5)")) << m;
  }
  EXPECT_EQ(load_project_config(write("[material]\npoisson_ratio = 0.33\n"))
                .design.material.poisson_ratio,
            0.33);
}

TEST_F(ProjectConfigTest, HingeGeometryIsChecked) {
  // t = 13 mm against the default R = 6 mm: the neck would be thicker than the notch diameter.
  std::string m = error_for("[hinge]\nthickness_m = 13e-3\n");
  EXPECT_TRUE(contains(m, "hinge.thickness_m")) << m;
  EXPECT_TRUE(contains(m, "hinge.radius_m")) << m;
  // L = 10 mm with R = 6 mm: the notches at the two ends of a link overlap.
  m = error_for("[hinge]\nlink_length_m = 10e-3\n");
  EXPECT_TRUE(contains(m, "hinge.link_length_m")) << m;
  EXPECT_TRUE(contains(m, "hinge.radius_m")) << m;
}

TEST_F(ProjectConfigTest, SyntaxErrorAndMissingFile) {
  std::string m = error_for("[hinge]\nwidth_m = 8e-3\nthickness_m 2e-3\n");
  EXPECT_TRUE(contains(m, ":3:")) << m;
  EXPECT_TRUE(contains(m, "syntax error")) << m;
  const std::string missing = (dir_ / "absent.toml").string();
  try {
    load_project_config(missing);
    ADD_FAILURE() << "no error for a missing file";
  } catch (const core::InputError& e) {
    EXPECT_TRUE(contains(e.what(), missing)) << e.what();
  }
}

TEST_F(ProjectConfigTest, ReadDesignSectionsLeavesUnknownKeysToTheCaller) {
  // The helper another section's reader mirrors: it reads, it does not reject.
  const ConfigFile f = ConfigFile::parse("[hinge]\nwidth_m = 9e-3\n[twin]\nseed = 1\n", "mem");
  design::DesignInputs d;
  read_design_sections(f, d);
  EXPECT_EQ(d.hinge.width_m, 9e-3);
  EXPECT_THROW(f.reject_unknown(), core::InputError);  // [twin] was nobody's
}

}  // namespace
}  // namespace piezoshift::io
