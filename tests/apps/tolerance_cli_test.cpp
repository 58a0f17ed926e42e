// `piezoshift tolerance` as a user runs it: the same study on one thread, two threads
// and two shards merged gives the same bytes; an interrupted run resumes; bad files exit 2. Six
// samples keep it short under the sanitizers; the 16-sample study, with a Dask
// cluster besides, is python/tests_dask.
#include <filesystem>
#include <set>

#include <nlohmann/json.hpp>

#include "../support/cli_test.hpp"
#include "../support/svg_text_check.hpp"

namespace piezoshift {
namespace {

using ToleranceCli = testing::CliTest;

// Two tolerances, three drawn values (the hinge and two legs' worth of stroke): a small study
// whose samples all differ.
constexpr const char* kTolerances = R"(
[tolerance.hinge.thickness_m]
distribution = "uniform"
lo = -10e-6
hi = 10e-6
source = "wire EDM"
[tolerance.twin.piezo.free_stroke_scale]
distribution = "normal"
sigma = 0.005
bound = 0.01
relative = true
source = "one batch of stacks"
)";

TEST_F(ToleranceCli, OneTwoThreadsAndTwoShardsGiveTheSameBytesAndARunResumes) {
  const std::string tol = write("tol.toml", kTolerances);
  const std::string spec = write("spec.toml", "[spec]\ntravel_semi_closed_um_min = 11.4\n");
  const std::string study = "tolerance --tolerances '" + tol + "' --samples 6 --seed 5 ";
  const testing::CliResult one = run(study + "--jobs 1 --spec '" + spec + "' --out " + path("j1"));
  ASSERT_EQ(one.status, 0) << one.err;
  EXPECT_NE(one.err.find("6/6 done"), std::string::npos) << one.err;  // the progress lines
  const testing::CliResult two =
      run(study + "--jobs 2 --figures --spec '" + spec + "' --out " + path("j2"));
  ASSERT_EQ(two.status, 0) << two.err;
  // The figures (a histogram and a cumulative curve per metric that varies) change no byte of
  // the JSON; their text does not overlap and their axes have units (docs/figures.md).
  int figures = 0;
  std::string problems;
  for (const std::string& p : testing::folder_figure_problems(path("j2"), figures))
    problems += p + "\n";
  EXPECT_EQ(problems, "");
  EXPECT_GE(figures, 6);
  for (const char* shard : {"0/2", "1/2"}) {
    const testing::CliResult s = run(study + "--jobs 1 --shard " + shard + " --out " + path("s"));
    ASSERT_EQ(s.status, 0) << s.err;
  }
  const testing::CliResult merged =
      run("tolerance merge " + path("s/shard-0-of-2.json") + " " + path("s/shard-1-of-2.json") +
          " --spec '" + spec + "' --out " + path("m"));
  ASSERT_EQ(merged.status, 0) << merged.err;
  const std::string bytes = read_text(path("j1/tolerance.json"));
  EXPECT_EQ(bytes, read_text(path("j2/tolerance.json")));
  EXPECT_EQ(bytes, read_text(path("m/tolerance.json")));
  EXPECT_EQ(read_text(path("j1/tolerance.csv")), read_text(path("m/tolerance.csv")));

  const auto j = nlohmann::json::parse(bytes);
  ASSERT_EQ(j["samples"].size(), 6U);
  EXPECT_EQ(j["samples"][5]["index"], 5);
  EXPECT_EQ(j["study"]["tolerances"].size(), 4U);  // t and three legs
  // Every sample counted: those that are not valid fail, never dropped.
  EXPECT_EQ(j["yield"]["samples"], 6);
  EXPECT_LE(j["yield"]["pass"].get<int>(), j["yield"]["valid"].get<int>());
  std::set<double> thickness;
  for (const auto& s : j["samples"])
    thickness.insert(s["values"]["hinge.thickness_m"].get<double>());
  EXPECT_EQ(thickness.size(), 6U);

  // Interrupted: two records lost; the rerun resumes the other 4 and gives the same bytes.
  std::filesystem::remove(path("j1/samples/sample-000001.json"));
  std::filesystem::remove(path("j1/samples/sample-000004.json"));
  const testing::CliResult again =
      run(study + "--jobs 1 --spec '" + spec + "' --out " + path("j1"));
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_NE(again.err.find("4 sample(s) resumed"), std::string::npos) << again.err;
  EXPECT_NE(again.err.find("2/2 done"), std::string::npos) << again.err;
  EXPECT_EQ(read_text(path("j1/tolerance.json")), bytes);

  // A worst sample reruns alone to the same numbers.
  const int k = j["worst"][0]["index"].get<int>();
  const testing::CliResult alone = run(study + "--sample " + std::to_string(k));
  ASSERT_EQ(alone.status, 0) << alone.err;
  auto rerun = nlohmann::json::parse(alone.out);
  rerun.erase("spec_failure");
  EXPECT_EQ(rerun, j["samples"][static_cast<std::size_t>(k)]);
}

TEST_F(ToleranceCli, BadTolerancesExit2NamingTheKey) {
  const std::string unknown =
      write("u.toml",
            "[tolerance.hinge.thicknes_m]\ndistribution = \"uniform\"\nlo = 0\nhi = 0\n"
            "source = \"x\"\n");
  testing::CliResult r = run("tolerance --tolerances '" + unknown + "' --samples 1");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("tolerance.hinge.thicknes_m"), std::string::npos) << r.err;
  const std::string range =
      write("r.toml",
            "[tolerance.material.poisson_ratio]\ndistribution = \"discrete\"\n"
            "values = [0.0, 0.25]\nsource = \"x\"\n");
  r = run("tolerance --tolerances '" + range + "' --samples 1");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("[tolerance.material.poisson_ratio]"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("valid range"), std::string::npos) << r.err;
  const std::string sampling =
      write("s.toml",
            "[tolerance.hinge.radius_m]\ndistribution = \"normal\"\nsigma = -1e-6\n"
            "bound = 1e-6\nsource = \"x\"\n");
  r = run("tolerance --tolerances '" + sampling + "' --samples 1");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("[tolerance.hinge.radius_m]: cannot be sampled"), std::string::npos)
      << r.err;
  r = run("tolerance --tolerances '" + sampling + "' --shard 2/2");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--shard"), std::string::npos) << r.err;
  // What a shard would ignore is refused, not dropped.
  const std::string good = write("g.toml", kTolerances);
  r = run("tolerance --tolerances '" + good + "' --shard 0/2 --sensitivity --out " + path("x"));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("run --sensitivity without --shard"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(path("x")));
  // A Dask scheduler runs whole studies: a shard of one is refused before any interpreter starts.
  r = run("tolerance --tolerances '" + good + "' --scheduler tcp://127.0.0.1:9 --shard 0/2 --out " +
          path("x"));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--scheduler runs a whole study"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(path("x")));
}

// What a shard file, --shard or --scheduler says is checked before it is used. A
// shard's header claiming 1e12 samples once ended merge in std::bad_alloc (exit 1); a file of '['
// took 5 GB to parse; --shard 2/18446744073709551615 wrapped round; --shard 5/8 --samples 4 ran
// nothing with a misleading message; --scheduler garbage ended in a Python traceback.
TEST_F(ToleranceCli, ShardFilesShardsAndSchedulersAreCheckedBeforeUse) {
  const std::string tol = write("tol.toml", kTolerances);
  const auto refused = [&](const std::string& args, const std::string& message) {
    const testing::CliResult r = run(args);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << args << "\n" << r.err;
    EXPECT_EQ(r.err.find("Traceback"), std::string::npos) << r.err;
  };
  const nlohmann::json header{
      {"tolerance_file", tol},       {"config", "built-in defaults"}, {"seed", 1},
      {"samples", 1000000000000ULL}, {"procedure", "paper"},          {"experiments", "quick"}};
  const std::string huge = write(
      "huge.json", nlohmann::json{{"study", header}, {"samples", nlohmann::json::array()}}.dump());
  refused("tolerance merge '" + huge + "' --out " + path("m"),
          huge + ": 1000000000000 samples; a study has 1 to 1000000 (docs/tolerance.md)");
  const std::string bomb = write("bomb.json", std::string(8u << 20, '['));
  refused("tolerance merge '" + bomb + "' --out " + path("m"),
          bomb + ": nests deeper than 16 levels; not a study's file");
  refused("tolerance --tolerances '" + tol + "' --samples 1000001", "--samples");
  refused("tolerance --tolerances '" + tol + "' --shard 2/18446744073709551615",
          "2/18446744073709551615 is not i/N with 0 <= i < N <= 1000000");
  refused("tolerance --tolerances '" + tol + "' --shard 5/8 --samples 4 --out " + path("s"),
          "tolerance --shard 5/8: 8 shards for 4 samples (--samples 4); N may be at most the "
          "sample count, so that every shard runs a sample");
  refused("tolerance --tolerances '" + tol + "' --scheduler garbage --out " + path("d"),
          "'garbage' is not a scheduler address; give SCHEME://HOST:PORT");
  refused("tolerance --tolerances '" + tol + "' --scheduler tcp://127.0.0.1 --out " + path("d"),
          "'tcp://127.0.0.1' needs a host and a port 1..65535");
  for (const char* out : {"m", "s", "d"})
    EXPECT_FALSE(std::filesystem::exists(path(out))) << out;
}

}  // namespace
}  // namespace piezoshift
