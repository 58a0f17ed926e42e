// The improved controller on plants it was not developed on: samples 0 to 7 of seed 50 of
// configs/tolerances/unseen_plants.toml (strokes, hysteresis, creep, plate thickness, payload
// drawn across docs/twin.md's ranges by the tolerance module's own draws), around
// configs/plants/drawn-nominal.toml (excitation drift off), each through `compare --quick`
// (reproduction::compare) and held to the targets of docs/compare.md, "Drawn plants".
//
// One seed per plant, and in `make test` the first two samples only: a plant's `compare --quick`
// costs 3.5 to 6 min of one core on this machine (a heavy plate's modes and stage 5b's 10 kHz
// bench), so all eight would add about half an hour of CPU to CI. The whole sweep is
// PIEZOSHIFT_DRAWN_SAMPLES=8 (read when the tests are listed: set it for the build, or run the
// binary with it); PIEZOSHIFT_DRAWN_SEEDS=N runs seeds 1..N instead of seed 1. The samples are
// the first N of the draw, not chosen by their results; docs/compare.md has each one's figures.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <string>

#include <fmt/core.h>

#include "piezoshift/config/project_config.hpp"
#include "piezoshift/reproduction/comparison.hpp"
#include "piezoshift/tolerance/tolerance_file.hpp"
#include "test_paths.hpp"

namespace piezoshift::reproduction {
namespace {

constexpr std::uint64_t kDrawSeed = 50;

config::ProjectConfig drawn_plant(std::uint64_t sample, std::string& described) {
  config::ProjectConfig c =
      config::load_project_config(testing::source_dir() + "/configs/plants/drawn-nominal.toml");
  tolerance::pin_identified_contact(c);
  const tolerance::ToleranceSet set = tolerance::load_tolerances(
      testing::source_dir() + "/configs/tolerances/unseen_plants.toml", c);
  const std::vector<double> d = tolerance::draw_deviations(set, kDrawSeed, sample);
  const std::string problem = tolerance::apply_deviations(set, d, c);
  EXPECT_EQ(problem, "");
  for (std::size_t i = 0; i < set.tolerances.size(); ++i)
    described +=
        fmt::format("{} {:.4g}; ", set.tolerances[i].key, set.tolerances[i].value_at(d[i]));
  return c;
}

const FigureValue& median(const ComparisonResult& r, const char* key, LoopVariant k) {
  return r.medians.at(r.figure_index(key))[static_cast<std::size_t>(k)];
}

class DrawnPlants : public ::testing::TestWithParam<int> {};

TEST_P(DrawnPlants, QuickCompareMeetsTheTargets) {
  std::string described;
  const config::ProjectConfig plant =
      drawn_plant(static_cast<std::uint64_t>(GetParam()), described);
  CompareOptions o;
  o.quick = true;
  const char* n = std::getenv("PIEZOSHIFT_DRAWN_SEEDS");
  const int seeds = n ? std::atoi(n) : 1;
  for (int s = 1; s <= std::max(1, seeds); ++s)
    o.seeds.push_back(static_cast<std::uint64_t>(s));
  const ComparisonResult r = compare(plant, o);
  const auto improved = [&](const char* key) { return median(r, key, LoopVariant::kImproved); };
  const auto oracle = [&](const char* key) { return median(r, key, LoopVariant::kOracleFeedback); };
  const auto ratio = [&](const char* key) { return improved(key).value / oracle(key).value; };
  const double step_1kHz = improved("phase_step_settling_time_s").value;
  const double step_10kHz = improved("phase_step_10kHz_settling_time_s").value;
  const double travel_gap =
      oracle("travel_semi_closed_um").value - improved("travel_semi_closed_um").value;
  fmt::print(
      "sample {}: {}\n  valid {}; grid linearity x oracle {:.2f} ({:.4f} / {:.4f} %); "
      "repeatability 5 / 10 um x oracle {:.2f} / {:.2f}; travel {:.1f} / {:.1f} um; "
      "lambda/8 step {:.1f} / {:.1f} ms; verdict: {}\n",
      GetParam(), described, r.valid(), ratio("linearity_grid_zero_end_pct"),
      improved("linearity_grid_zero_end_pct").value, oracle("linearity_grid_zero_end_pct").value,
      ratio("repeatability_5um_nm"), ratio("repeatability_10um_nm"),
      improved("travel_semi_closed_um").value, oracle("travel_semi_closed_um").value,
      1e3 * step_1kHz, 1e3 * step_10kHz, r.rate_verdict.empty() ? "none" : r.rate_verdict);
  for (const std::string& why : r.invalid_reasons())
    ADD_FAILURE() << why;
  EXPECT_TRUE(r.valid());
  EXPECT_LE(ratio("linearity_grid_zero_end_pct"), 1.25);
  EXPECT_LE(ratio("repeatability_5um_nm"), 1.25);
  EXPECT_LE(ratio("repeatability_10um_nm"), 1.25);
  EXPECT_LE(travel_gap, 0.1 + 1e-9);
  EXPECT_LE(step_10kHz, 2e-3 + 1e-9);
  // 5 ms at 1 kHz, or 10 ms where the calibration names the plate's mode as the reason.
  EXPECT_LE(step_1kHz, (r.rate_verdict.empty() ? 5e-3 : kModeLimitedPhaseStep_s) + 1e-9)
      << r.rate_verdict;
}

int drawn_samples() {
  const char* n = std::getenv("PIEZOSHIFT_DRAWN_SAMPLES");
  const int samples = n ? std::atoi(n) : 2;
  return std::clamp(samples, 1, 8);
}

INSTANTIATE_TEST_SUITE_P(Seed50, DrawnPlants, ::testing::Range(0, drawn_samples()),
                         [](const auto& param_info) {
                           return fmt::format("sample_{}", param_info.param);
                         });

}  // namespace
}  // namespace piezoshift::reproduction
