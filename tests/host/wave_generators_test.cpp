// The wave generators' host side on its own: WSL/WGC/WTR settings and their error numbers, what
// a start hands the loop (the table's copy in alternating slots, rate, cycles, the axis's column),
// the running state as the loop's samples report it, and WGO's check of the tables as a whole.
#include <gtest/gtest.h>

#include <string_view>
#include <vector>

#include "piezoshift/host/wave_generators.hpp"
#include "piezoshift/plant/geometry.hpp"

namespace piezoshift::host {
namespace {

using Action = runtime::WaveCommand::Action;

class WaveGeneratorsTest : public ::testing::Test {
 protected:
  WaveGeneratorsTest() : model_(stage_model_params(plant::GeometryParams{})), waves_(model_) {}

  // "WAV t X PNT 1 n v..." with the values given as text.
  GcsError points(int table, const std::vector<std::string_view>& values) {
    std::vector<std::string_view> args{"X", "PNT", "1"};
    const std::string n = std::to_string(values.size());
    args.push_back(n);
    args.insert(args.end(), values.begin(), values.end());
    return waves_.define(table, args);
  }

  StageModel model_;
  WaveGenerators waves_;
};

TEST_F(WaveGeneratorsTest, SettingsCheckTheirRangesAllOrNothing) {
  EXPECT_EQ(waves_.table(2), 3);  // generator n plays table n by default
  EXPECT_EQ(waves_.select({{0, 5}, {1, 9}}), GcsError::kWaveIndex);
  EXPECT_EQ(waves_.table(0), 1);  // the refused WSL set nothing
  EXPECT_EQ(waves_.select({{0, 5}, {1, 0}}), GcsError::kNone);
  EXPECT_EQ(waves_.table(0), 5);
  EXPECT_EQ(waves_.table(1), 0);
  EXPECT_EQ(waves_.set_cycles({{0, 2}, {1, -1}}), GcsError::kParamOutOfRange);
  EXPECT_EQ(waves_.cycles(0), 0);
  EXPECT_EQ(waves_.set_cycles({{2, 0xFFFFFFFF}}), GcsError::kNone);
  EXPECT_EQ(waves_.cycles(2), 0xFFFFFFFF);
  EXPECT_EQ(waves_.set_cycles({{2, 0x100000000}}), GcsError::kParamOutOfRange);
  EXPECT_EQ(WaveGenerators::check_rate(1000000, 0), GcsError::kNone);
  EXPECT_EQ(WaveGenerators::check_rate(1000001, 0), GcsError::kParamOutOfRange);
  EXPECT_EQ(WaveGenerators::check_rate(0, 0), GcsError::kParamOutOfRange);
  EXPECT_EQ(WaveGenerators::check_rate(5, 1), GcsError::kParamOutOfRange);
}

TEST_F(WaveGeneratorsTest, AStartHandsTheLoopACopyInTheSlotItDoesNotRead) {
  ASSERT_EQ(points(1, {"0.5", "1.5", "2.5"}), GcsError::kNone);
  waves_.set_rate(0, 4);
  ASSERT_EQ(waves_.set_cycles({{0, 2}}), GcsError::kNone);
  const runtime::HostCommand c = waves_.start_command(0, 3.0);
  EXPECT_EQ(c.kind, runtime::HostCommand::Kind::kWave);
  EXPECT_EQ(c.wave.action, Action::kStart);
  EXPECT_EQ(c.wave.generator, 0);
  ASSERT_NE(c.wave.values, nullptr);
  EXPECT_NE(c.wave.values, waves_.tables().values(1).data());  // a copy, not WAV's own table
  EXPECT_EQ(c.wave.length, 3u);
  EXPECT_EQ(c.wave.values[2], 2.5);
  EXPECT_EQ(c.wave.rate, 4u);
  EXPECT_EQ(c.wave.cycles, 2u);
  EXPECT_EQ(c.wave.reference, 3.0);
  for (std::size_t i = 0; i < 3; ++i)  // Z moves the three points alike
    EXPECT_NEAR(c.wave.points_per_unit[i], 1.0, 1e-12) << i;
  waves_.started(0, 1, 7);
  EXPECT_TRUE(waves_.running(0));
  EXPECT_EQ(waves_.mode(0), 1);
  EXPECT_EQ(waves_.running_mask(), 1u);
  // The next start takes the pair's other slot, the one after that the first again.
  const double* second = waves_.start_command(0, 3.0).wave.values;
  EXPECT_NE(second, c.wave.values);
  waves_.started(0, 1, 8);
  EXPECT_EQ(waves_.start_command(0, 3.0).wave.values, c.wave.values);
  // Generator 2 has slots of its own.
  ASSERT_EQ(points(2, {"1"}), GcsError::kNone);
  const double* other = waves_.start_command(1, 0.0).wave.values;
  EXPECT_NE(other, c.wave.values);
  EXPECT_NE(other, second);
}

TEST_F(WaveGeneratorsTest, ThePlayingTableAndItsGeneratorCannotBeChanged) {
  ASSERT_EQ(points(1, {"1", "2"}), GcsError::kNone);
  waves_.started(0, 1, 1);
  EXPECT_EQ(points(1, {"3"}), GcsError::kWaveGeneratorActive);
  EXPECT_EQ(waves_.tables().values(1).size(), 2u);
  EXPECT_EQ(points(2, {"3"}), GcsError::kNone);
  EXPECT_EQ(waves_.select({{1, 4}, {0, 2}}), GcsError::kWaveGeneratorActive);
  EXPECT_EQ(waves_.table(1), 2);  // all or nothing
  EXPECT_EQ(waves_.select({{1, 4}}), GcsError::kNone);
}

TEST_F(WaveGeneratorsTest, TheSamplesSayWhenAGeneratorStopsFromTheAppliedStartOn) {
  ASSERT_EQ(points(3, {"1", "2"}), GcsError::kNone);
  waves_.started(2, 1, 5);
  EXPECT_FALSE(waves_.applied(2, 4));
  EXPECT_FALSE(waves_.playing(2, 4));
  EXPECT_EQ(waves_.update(4, 0), 0u);  // from before the loop took the start: not news
  EXPECT_TRUE(waves_.running(2));
  EXPECT_EQ(waves_.update(5, 0b100), 0u);
  EXPECT_TRUE(waves_.playing(2, 5));
  EXPECT_EQ(waves_.update(6, 0), 0b100u);  // its cycles done
  EXPECT_FALSE(waves_.running(2));
  EXPECT_EQ(waves_.mode(2), 0);
  EXPECT_EQ(waves_.running_mask(), 0u);
  EXPECT_EQ(waves_.update(7, 0), 0u);  // reported once
  const runtime::HostCommand stop = WaveGenerators::stop_command(1);
  EXPECT_EQ(stop.wave.action, Action::kStop);
  EXPECT_EQ(stop.wave.generator, 1);
  ASSERT_EQ(points(2, {"1"}), GcsError::kNone);
  waves_.started(1, 1, 8);
  EXPECT_TRUE(waves_.active(1));
  waves_.stopped(1, 9);
  EXPECT_FALSE(waves_.active(1));
  EXPECT_FALSE(waves_.applied(1, 8));
}

TEST_F(WaveGeneratorsTest, AStartIsCheckedAsAWholePose) {
  const AxisValues at{5.0, 0.0, 0.0};
  EXPECT_EQ(waves_.check_start({true, false, false}, at), GcsError::kWaveNotDefined);
  ASSERT_EQ(points(1, {"4", "6"}), GcsError::kNone);
  EXPECT_EQ(waves_.check_start({true, false, false}, at), GcsError::kNone);
  ASSERT_EQ(points(2, {"1", "50"}), GcsError::kNone);
  EXPECT_EQ(waves_.check_start({true, true, false}, at), GcsError::kNone);
  ASSERT_EQ(points(3, {"1000"}), GcsError::kNone);  // urad: far beyond V's travel
  EXPECT_EQ(waves_.check_start({false, false, true}, at), GcsError::kPositionOutOfLimits);
  // Z at 6 um is fine alone; from a Z of 20 um the box is not.
  EXPECT_EQ(waves_.check_start({false, true, false}, AxisValues{20.0, 0.0, 0.0}),
            GcsError::kPositionOutOfLimits);
  ASSERT_EQ(waves_.select({{0, 0}}), GcsError::kNone);
  EXPECT_EQ(waves_.check_start({true, false, false}, at), GcsError::kWaveNotDefined);
}

}  // namespace
}  // namespace piezoshift::host
