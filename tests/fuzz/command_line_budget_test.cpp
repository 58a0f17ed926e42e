// The command_line fuzz target reaches every subcommand within a bounded cost: one
// well-formed command line per subcommand passes all of its checks and stops where its costly
// work would begin (app::work_begins), having simulated nothing and written no file. Counted,
// not timed: the twin's ticks, physics steps and static measurements (rig::simulation_meter)
// and the files in the output folder, before and after each.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "../support/test_paths.hpp"
#include "command.hpp"
#include "entry_points.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/psi/png_image.hpp"
#include "piezoshift/psi/surface_file.hpp"
#include "piezoshift/rig/simulation_meter.hpp"
#include "piezoshift/tolerance/study_run.hpp"

namespace piezoshift::fuzz {
namespace {

namespace fs = std::filesystem;

struct Case {
  std::vector<std::string> args;  // after the program's name
  Outcome expected = Outcome::kStoppedAtWork;
};

std::size_t files_under(const fs::path& dir) {
  std::size_t n = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    n += e.is_regular_file() ? 1 : 0;
  return n;
}

// Every leaf of the program's command tree: "fit matrix", "run", ...
std::vector<std::string> subcommand_paths() {
  CLI::App app;
  app::Action action;
  app::build_program(app, action);
  std::vector<std::string> paths;
  for (const CLI::App* sub : app.get_subcommands({})) {
    const std::vector<const CLI::App*> leaves = sub->get_subcommands({});
    if (leaves.empty())
      paths.push_back(sub->get_name());
    for (const CLI::App* leaf : leaves)
      paths.push_back(sub->get_name() + " " + leaf->get_name());
  }
  return paths;
}

class CommandLineBudget : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / fmt::format("piezoshift-cl-budget-{}", ::getpid());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "frames");
    // Five 32 x 32 frames for psi analyze and psi calibrate (their reading is a check).
    for (int k = 0; k < 5; ++k) {
      psi::Map frame(32, 32, 1000.0 + 100.0 * k);
      psi::write_png_gray16((dir_ / "frames" / fmt::format("f{}.png", k)).string(), frame);
    }
    // Two 32 x 32 maps for psi compare (reading them is a check; the fits are its work).
    for (const char* name : {"a.gsf", "b.gsf"})
      psi::write_gsf((dir_ / name).string(), {psi::Map(32, 32, 1.0), 1e-4, name});
  }
  void TearDown() override { fs::remove_all(dir_); }

  // tolerance merge's input: a shard of a one-sample study of the example tolerances, its one
  // record a sample that was not valid (merging reads it; nothing is computed).
  std::string tolerance_shard() const {
    tolerance::StudyInputs study;
    study.tolerances = testing::source_dir() + "/configs/tolerances/paper_stage.toml";
    study.samples = 1;
    const tolerance::Study s = tolerance::load_study(study);
    const tolerance::ToleranceSet& set = s.set;
    const nlohmann::json& header = s.header;
    tolerance::SampleResult r;
    r.deviations.assign(set.tolerances.size(), 0.0);
    r.metrics.assign(tolerance::metrics().size(), std::nan(""));
    r.valid = false;
    r.reason = "made by the test";
    const nlohmann::json shard{
        {"study", header}, {"shard", {0, 1}}, {"samples", {tolerance::sample_json(set, r)}}};
    std::FILE* f = std::fopen(in("shard.json").c_str(), "w");
    std::fputs(shard.dump().c_str(), f);
    std::fclose(f);
    return in("shard.json");
  }

  std::string in(const char* name) const { return (dir_ / name).string(); }
  std::string frame(int k) const { return (dir_ / "frames" / fmt::format("f{}.png", k)).string(); }
  std::map<std::string, Case> cases() const;

  fs::path dir_;
};

std::map<std::string, Case> CommandLineBudget::cases() const {
  const std::string csv = testing::source_dir() + "/fuzz/corpus/csv/";
  const std::string out = in("out");
  std::vector<std::string> psi_frames;
  for (int k = 0; k < 5; ++k)
    psi_frames.push_back(frame(k));
  Case psi_analyze{{"psi", "analyze"}};
  psi_analyze.args.insert(psi_analyze.args.end(), psi_frames.begin(), psi_frames.end());
  psi_analyze.args.insert(psi_analyze.args.end(), {"--out", out});
  Case psi_calibrate{{"psi", "calibrate"}};
  psi_calibrate.args.insert(psi_calibrate.args.end(), psi_frames.begin(), psi_frames.end());
  psi_calibrate.args.insert(psi_calibrate.args.end(), {"--out", out + "/steps.toml"});
  return {
      // No costly work without --search: the design is evaluated and printed whole.
      {"design", {{"design", "--search", "--top", "3"}}},
      {"simulate", {{"simulate", "--step-um", "5", "--duration-s", "0.2", "--json"}}},
      {"fit matrix",
       {{"fit", "matrix", "--data", csv + "matrix_poses.csv", "--out", out + ".toml"}}},
      {"fit poly",
       {{"fit", "poly", "--data", csv + "polynomial_points.csv", "--out", out + ".toml"}}},
      {"fit improved", {{"fit", "improved", "--data", in("record.csv")}}},
      {"analyze linearity",
       {{"analyze", "linearity", "--data", csv + "linearity.csv", "--plot", out + ".svg"}}},
      {"analyze repeatability",
       {{"analyze", "repeatability", "--data", csv + "repeatability_5um.csv", "--plot",
         out + ".svg"}}},
      {"analyze step",
       {{"analyze", "step", "--data", csv + "step_response.csv", "--step-time-s", "0.001", "--plot",
         out + ".svg"}}},
      {"run", {{"run", "--daq", "sim", "--duration-s", "1", "--fault", "sgs-open@0.5:1"}}},
      {"calibrate", {{"calibrate", "--out", out + ".toml"}}},
      {"serve", {{"serve", "--daq", "sim", "--port", "0", "--duration-s", "1"}}},
      {"gcs", {{"gcs", "--port", "50000", "POS?"}}},
      {"reproduce", {{"reproduce", "--quick", "--out", out}}},
      {"compare", {{"compare", "--seeds", "1-3", "--quick", "--out", out}}},
      {"psi simulate", {{"psi", "simulate", "--out", out}}},
      {"psi analyze", psi_analyze},
      {"psi calibrate", psi_calibrate},
      {"psi compare", {{"psi", "compare", in("a.gsf"), in("b.gsf"), "--out", out}}},
      {"measure", {{"measure", "--camera", "twin", "--out", out}}},
      {"tolerance",
       {{"tolerance", "--tolerances",
         testing::source_dir() + "/configs/tolerances/paper_stage.toml", "--samples", "4", "--out",
         out}}},
      {"tolerance merge", {{"tolerance", "merge", tolerance_shard(), "--out", out}}},
  };
}

TEST_F(CommandLineBudget, EverySubcommandStopsBeforeItsWork) {
  // fit improved's record: evenly spaced, every column it requires.
  {
    std::FILE* f = std::fopen(in("record.csv").c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs("t_s,u1_um,u2_um,u3_um,sgs1_um,sgs2_um,sgs3_um\n", f);
    for (int k = 0; k < 100; ++k)
      std::fprintf(f, "%.4f,%d,%d,%d,%d,%d,%d\n", 1e-4 * k, k % 7, k % 7, k % 7, k % 5, k % 5,
                   k % 5);
    std::fclose(f);
  }
  const std::map<std::string, Case> all = cases();
  for (const std::string& path : subcommand_paths())
    EXPECT_EQ(all.count(path), 1u) << "no command line for `" << path << "`";

  for (const auto& [path, c] : all) {
    SCOPED_TRACE(path);
    std::string input;
    for (const std::string& a : c.args)
      input += a + "\n";
    const std::size_t files = files_under(dir_);
    const rig::SimulationMeter before = rig::simulation_meter();
    const Outcome outcome = command_line(input);
    const rig::SimulationMeter after = rig::simulation_meter();
    EXPECT_EQ(static_cast<int>(outcome), static_cast<int>(c.expected));
    EXPECT_EQ(after.ticks - before.ticks, 0u);
    EXPECT_EQ(after.physics_steps - before.physics_steps, 0u);
    EXPECT_EQ(after.static_measurements - before.static_measurements, 0u);
    EXPECT_EQ(files_under(dir_), files) << "a file was written";
  }
}

// design without --search has no costly work: it runs whole, and a bad value is still refused.
TEST_F(CommandLineBudget, DesignRunsWholeAndBadInputIsRefused) {
  EXPECT_EQ(static_cast<int>(command_line("design\n--json\n")),
            static_cast<int>(Outcome::kCompleted));
  EXPECT_EQ(static_cast<int>(command_line("run\n--daq\nnope\n--duration-s\n1\n")),
            static_cast<int>(Outcome::kRefused));
  EXPECT_EQ(static_cast<int>(command_line("simulate\n--step-um\n5\n--duration-s\n-1\n")),
            static_cast<int>(Outcome::kRefused));
}

}  // namespace
}  // namespace piezoshift::fuzz
