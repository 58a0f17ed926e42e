// Runs the piezoshift program (`design` subcommand) and checks its output and exit status.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../support/cli_test.hpp"

namespace {

using RunResult = piezoshift::testing::CliResult;
class DesignCommand : public piezoshift::testing::CliTest {
 protected:
  // A configuration that `design` must refuse: exit 2, the file and the key named, no stdout.
  void expect_refused(const std::string& text, const std::string& key) {
    const std::string path = write("bad.toml", text);
    const RunResult r = run("design --config '" + path + "'");
    EXPECT_EQ(r.status, 2) << text << "\n" << r.err;
    EXPECT_NE(r.err.find(path), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(key), std::string::npos) << r.err;
    EXPECT_EQ(r.out, "") << "nothing on stdout for bad input";
  }
};

TEST_F(DesignCommand, JsonHasThePaperNumbers) {
  const RunResult r = run("design --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j.at("angular_stiffness_Nm_per_rad").get<double>(), 274.44, 0.01);
  EXPECT_NEAR(j.at("mechanism_stiffness_N_per_um").get<double>(), 6.776, 0.001);
  EXPECT_NEAR(j.at("available_displacement_um").get<double>(), 14.588, 0.001);
  EXPECT_NEAR(j.at("stiffness_ratio").get<double>(), 0.0968, 0.0001);
  EXPECT_TRUE(j.at("rule_ka_over_10_ok").get<bool>());
  EXPECT_NEAR(j.at("max_stress_at_stroke_Pa").get<double>(), 44.70e6, 0.01e6);
  EXPECT_NEAR(j.at("stress_margin").get<double>(), 7.94, 0.01);
  EXPECT_TRUE(j.at("stress_ok").get<bool>());
  EXPECT_NEAR(j.at("natural_frequency_Hz").get<double>(), 1839.0, 0.5);
  EXPECT_TRUE(j.at("config_file").is_null());
  EXPECT_DOUBLE_EQ(j.at("inputs").at("hinge").at("thickness_m").get<double>(), 2e-3);
}

TEST_F(DesignCommand, TextReportShowsTheNumbersWithUnits) {
  const RunResult r = run("design");
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* s : {"274.44 N m/rad", "6.776 N/um", "7.000 N/um", "14.588 um", "44.70 MPa",
                        "1839.1 Hz", "paper: 6.78 N/um", "paper's FEA: 47.63 MPa"}) {
    EXPECT_NE(r.out.find(s), std::string::npos) << s << "\n" << r.out;
  }
}

TEST_F(DesignCommand, PaperTomlGivesTheSameReport) {
  const std::string paper = piezoshift::testing::source_dir() + "/configs/paper.toml";
  const RunResult a = run("design --json");
  const RunResult b = run("design --json --config '" + paper + "'");
  ASSERT_EQ(b.status, 0) << b.err;
  auto ja = nlohmann::json::parse(a.out);
  auto jb = nlohmann::json::parse(b.out);
  EXPECT_EQ(jb.at("config_file").get<std::string>(), paper);
  ja.erase("config_file");
  jb.erase("config_file");
  EXPECT_EQ(ja, jb);
}

TEST_F(DesignCommand, ConfigChangesTheDesign) {
  // The aluminium hinge of tests/design/flexure_test.cpp: k_m = 1.2204 N/um by hand.
  const std::string path = write("al.toml",
                                 "[material]\nelastic_modulus_Pa = 70e9\n"
                                 "[hinge]\nwidth_m = 10e-3\nthickness_m = 1.5e-3\n"
                                 "radius_m = 5e-3\nlink_length_m = 20e-3\n");
  const RunResult r = run("design --json --config '" + path + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j.at("mechanism_stiffness_N_per_um").get<double>(), 1.2204, 0.0001);
  EXPECT_NEAR(j.at("available_displacement_um").get<double>(), 15.7258, 0.0001);
}

TEST_F(DesignCommand, BadConfigurationsExitWithStatusTwo) {
  expect_refused("[hinge]\nthicknes_m = 2e-3\n", "hinge.thicknes_m");  // unknown key
  expect_refused("[actuatr]\nstiffness_N_per_um = 70\n", "actuatr");   // unknown section
  expect_refused("[actuator]\nstiffness_N_per_um = \"70\"\n", "actuator.stiffness_N_per_um");
  expect_refused("[material]\nallowable_stress_Pa = -355e6\n", "material.allowable_stress_Pa");
  expect_refused("[hinge]\nwidth_m = 0.0\n", "hinge.width_m");  // zero
  expect_refused("[mechanism]\nmoving_mass_kg = nan\n", "mechanism.moving_mass_kg");
  expect_refused("[material]\npoisson_ratio = 0.5\n", "material.poisson_ratio");
  expect_refused("[hinge]\nthickness_m = 13e-3\n", "hinge.radius_m");  // t > 2R
  expect_refused("[hinge]\nwidth_m = = 8e-3\n", ":2:");                // syntax, line 2
}

TEST_F(DesignCommand, MissingConfigFileExitsWithStatusTwo) {
  const std::string path = (dir_ / "absent.toml").string();
  const RunResult r = run("design --config '" + path + "'");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find(path), std::string::npos) << r.err;
}

TEST_F(DesignCommand, SearchJsonFindsThePaperHinge) {
  // Only t varies (R, b, L at Table 3): the stiffest hinge under k_a/10 is t = 2.0 mm.
  const RunResult r =
      run("design --search --json --top 3 --thickness-mm 1 3 0.1 --radius-mm 6,6,1 "
          "--width-mm 8 8 1 --length-mm 18 18 1");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("evaluated_count").get<int>(), 21);
  EXPECT_EQ(j.at("feasible_count").get<int>(), 11);
  const auto& c = j.at("candidates");
  ASSERT_EQ(c.size(), 3u);
  EXPECT_NEAR(c[0].at("thickness_m").get<double>(), 2.0e-3, 1e-12);
  EXPECT_NEAR(c[0].at("mechanism_stiffness_N_per_um").get<double>(), 6.776, 0.001);
  for (const auto& cand : c) {
    EXPECT_LE(cand.at("stiffness_ratio").get<double>(), 0.1);
    EXPECT_GE(cand.at("stress_margin").get<double>(), 2.0);
  }
}

TEST_F(DesignCommand, SearchTextListsRankedCandidates) {
  const RunResult r = run("design --search --top 4");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("48906 geometries"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("best 4 by natural frequency"), std::string::npos) << r.out;
}

TEST_F(DesignCommand, BadSearchOptionsExitWithStatusTwo) {
  RunResult r = run("design --search --thickness-mm 3 1 0.1");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--thickness-mm"), std::string::npos) << r.err;
  r = run("design --search --radius-mm 1 10 0");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--radius-mm"), std::string::npos) << r.err;
  r = run("design --search --min-stress-margin nan");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--min-stress-margin"), std::string::npos) << r.err;
  r = run("design --search --rank-by beauty");
  EXPECT_EQ(r.status, 2);
  r = run("design --top 3");  // a search option without --search
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--search"), std::string::npos) << r.err;
}

}  // namespace
