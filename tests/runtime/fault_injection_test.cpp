#include "piezoshift/runtime/fault_injection.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "fake_backend.hpp"
#include "piezoshift/core/input_error.hpp"

namespace piezoshift::runtime {
namespace {

using testing::FakeBackend;

TEST(FaultSpec, ParsesKindTimeAndOneBasedChannel) {
  const FaultSpec a = parse_fault_spec("sgs-open@0.25:3");
  EXPECT_EQ(a.kind, FaultKind::kSgsOpen);
  EXPECT_DOUBLE_EQ(a.time_s, 0.25);
  EXPECT_EQ(a.channel, 2);
  const FaultSpec b = parse_fault_spec("actuator-crack@1");
  EXPECT_EQ(b.kind, FaultKind::kActuatorCrack);
  EXPECT_EQ(b.channel, 0) << "channel 1 by default";
  const FaultSpec c = parse_fault_spec("overrun-burst@0.5");
  EXPECT_EQ(c.channel, -1);
  for (std::size_t k = 0; k < kFaultKinds; ++k) {
    const auto kind = static_cast<FaultKind>(k);
    EXPECT_EQ(parse_fault_spec(std::string(to_string(kind)) + "@0").kind, kind);
  }
}

TEST(FaultSpec, RejectsMalformedTextNamingIt) {
  for (const char* bad : {"sgs-open", "sgs-melt@1", "sgs-open@-1", "sgs-open@x", "sgs-open@1:4",
                          "sgs-open@1:0", "overrun-burst@1:2", "adc-nan@nan"}) {
    try {
      parse_fault_spec(bad);
      ADD_FAILURE() << bad << " accepted";
    } catch (const core::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
}

struct Rig {
  FakeBackend daq;
  SimulatedClock clock;
  FaultInjectingBackend faulty;
  explicit Rig(FaultSpec f, PlantFaultHooks* hooks = nullptr)
      : faulty(daq, clock, 1'000'000, {f}, FaultInjectionParams{}, hooks) {
    faulty.configure();
    faulty.activate();
  }
  Vec3 tick(std::uint64_t k, const Vec3& ao) {
    Vec3 ai{};
    faulty.read(CycleTime{k, static_cast<std::int64_t>(k) * 1'000'000, 1'000'000}, ai);
    faulty.write(CycleTime{k, static_cast<std::int64_t>(k) * 1'000'000, 1'000'000}, ao);
    return ai;
  }
};

TEST(FaultInjection, EmulatedSensorFaultsStartAtTheFirstTickAtOrAfterTheirTime) {
  Rig open(FaultSpec{FaultKind::kSgsOpen, 0.0105, 1});
  Rig stuck(FaultSpec{FaultKind::kSgsStuck, 0.0105, 2});
  Rig nan(FaultSpec{FaultKind::kAdcNan, 0.0105, 0});
  double frozen = 0.0;
  for (std::uint64_t k = 0; k < 15; ++k) {
    const Vec3 ao = control::filled(0.2 * static_cast<double>(k));  // a rising stage
    const Vec3 a = open.tick(k, ao);
    const Vec3 b = stuck.tick(k, ao);
    const Vec3 c = nan.tick(k, ao);
    if (k < 11) {
      EXPECT_LT(a[1], 9.0);
      frozen = b[2];
      EXPECT_TRUE(std::isfinite(c[0]));
    } else {
      EXPECT_EQ(a[1], 10.0) << "open bridge: the conditioner's rail, clipped by the ADC";
      EXPECT_EQ(b[2], frozen) << "stuck at the last healthy value";
      EXPECT_LT(b[1], b[0] + 1e-12);
      EXPECT_GT(b[1], frozen);
      EXPECT_TRUE(std::isnan(c[0]));
    }
  }
  EXPECT_EQ(open.faulty.injected_tick(0), 11U);
  EXPECT_EQ(stuck.faulty.first_injected_tick(), 11U);
}

TEST(FaultInjection, SpikeIsOneSampleTowardsTheFarEndAndClipsAtFullScale) {
  Rig low(FaultSpec{FaultKind::kAdcSpike, 0.005, 0});
  Vec3 before{};
  for (std::uint64_t k = 0; k < 5; ++k)
    before = low.tick(k, control::filled(1.0));
  const Vec3 spiked = low.tick(5, control::filled(1.0));
  const Vec3 after = low.tick(6, control::filled(1.0));
  EXPECT_NEAR(spiked[0] - spiked[1], 6.0, 1e-12) << "only channel 1, +6 V below mid-range";
  EXPECT_NEAR(after[0], after[1], 1e-12) << "gone on the next sample";
  (void)before;

  Rig high(FaultSpec{FaultKind::kAdcSpike, 0.0, 0});
  high.daq.activate();
  // drive the fake plant high first through a plain backend tick sequence
  FakeBackend& plant = high.daq;
  Vec3 ai{};
  for (std::uint64_t k = 0; k < 50; ++k) {
    plant.write(CycleTime{k, 0, 1'000'000}, control::filled(9.0));
    plant.read(CycleTime{k, 0, 1'000'000}, ai);
  }
  ASSERT_GT(ai[0], 5.0);
  const Vec3 s = high.tick(0, control::filled(9.0));
  EXPECT_NEAR(s[0], ai[0] - 6.0 + (s[1] - ai[1]), 1e-9) << "-6 V above mid-range";
}

TEST(FaultInjection, EmulatedAmplifierFailZeroesTheChannelsOutput) {
  Rig rig(FaultSpec{FaultKind::kAmplifierFail, 0.002, 2});
  for (std::uint64_t k = 0; k < 5; ++k)
    rig.tick(k, control::filled(4.0));
  EXPECT_EQ(rig.daq.last_written[2], 0.0);
  EXPECT_EQ(rig.daq.last_written[1], 4.0);
}

TEST(FaultInjection, PlantFaultsGoThroughTheHooks) {
  FakeBackend hooks_target;
  Rig rig(FaultSpec{FaultKind::kActuatorCrack, 0.001, 1}, &hooks_target);
  rig.tick(0, Vec3{});
  EXPECT_NEAR(hooks_target.gain(1), 70.0 / (70.0 + 6.78), 1e-12);
  rig.tick(1, Vec3{});
  // k_a -> 0.05 k_a: G = 3.5 / (3.5 + 6.78)
  EXPECT_NEAR(hooks_target.gain(1), 3.5 / 10.28, 1e-12);
  EXPECT_NEAR(hooks_target.gain(0), 70.0 / 76.78, 1e-12);
}

TEST(FaultInjection, CrackNeedsAPlantModel) {
  FakeBackend daq;
  SimulatedClock clock;
  EXPECT_THROW(
      FaultInjectingBackend(daq, clock, 1'000'000, {FaultSpec{FaultKind::kActuatorCrack, 0.1, 0}}),
      core::InputError);
}

}  // namespace
}  // namespace piezoshift::runtime
