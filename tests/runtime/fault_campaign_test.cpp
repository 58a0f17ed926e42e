// The randomized fault campaign on the twin (docs/safety.md, "Detection latencies"): fixed seeds,
// every fault kind at random times and channels, plus fault-free runs. Each scenario runs the
// real loop (controller, supervisor, sim backend, fault injector) on a simulated clock:
//
//   profile   a staircase alternating every 40 ms between a low level in [1, 4] um and a high
//             level in [6, 9] um (Z_d1 = Z_d2 = Z_d3), 0.3 s, at 1 kHz (the paper's rate)
//   fault     kind k, time uniform in [0.08, 0.2] s, channel uniform in 1..3
//
// and asserts, for every scenario:
//   - no output ever left 0..10 V or moved faster than 1.5 V/ms (the fault ramp included),
//   - a fault-free run latches nothing,
//   - a faulted run latches a fault whose reason is one the kind may cause, within the kind's
//     stated latency (ticks from the first tick the fault acts to the tick it is latched).
// The stated latencies are the table in docs/safety.md; the worst latencies seen are printed.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "piezoshift/runtime/control_loop.hpp"
#include "piezoshift/runtime/fault_injection.hpp"
#include "piezoshift/runtime/sim_backend.hpp"

namespace piezoshift::runtime {
namespace {

constexpr double kRate_Hz = 1000.0;
constexpr double kDuration_s = 0.45;
constexpr double kStair_s = 0.08;

struct Expectation {
  FaultKind kind;
  std::uint64_t max_latency_ticks;  // docs/safety.md, at 1 kHz
  std::set<FaultReason> reasons;
};

// docs/safety.md states these; keep the two in step.
const std::array<Expectation, kFaultKinds> kExpected{{
    {FaultKind::kSgsOpen, 0, {FaultReason::kSgsRail}},
    {FaultKind::kSgsStuck,
     130,
     {FaultReason::kResponse, FaultReason::kTracking, FaultReason::kSaturation}},
    {FaultKind::kAdcNan, 0, {FaultReason::kSgsNotFinite}},
    {FaultKind::kAdcSpike,
     0,
     {FaultReason::kSgsJump, FaultReason::kSgsRail, FaultReason::kSgsRange}},
    {FaultKind::kAmplifierFail,
     40,
     {FaultReason::kResponse, FaultReason::kTracking, FaultReason::kSaturation,
      FaultReason::kSgsJump}},
    // A stack at 5 % of its stiffness changes the loop's plant: some seeds ring into the
    // oscillation rule before the response rule's 20 ms.
    {FaultKind::kActuatorCrack,
     150,
     {FaultReason::kResponse, FaultReason::kTracking, FaultReason::kSaturation,
      FaultReason::kSgsJump, FaultReason::kOscillation}},
    {FaultKind::kOverrunBurst, 3, {FaultReason::kOverruns}},
}};

struct Outcome {
  LoopResult result;
  std::uint64_t injected_tick = FaultInjectingBackend::kNotYet;
  std::string label;
};

SetpointProfile staircase(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> low(1.0, 4.0);
  std::uniform_real_distribution<double> high(6.0, 9.0);
  std::vector<double> t;
  std::vector<Vec3> z;
  const int stairs = static_cast<int>(std::ceil(kDuration_s / kStair_s)) + 1;
  for (int i = 0; i < stairs; ++i) {
    const double level = (i % 2 == 0) ? low(rng) : high(rng);
    const double t0 = i * kStair_s;
    if (i > 0) {  // a 1 ms edge, so the profile is a function of time
      t.push_back(t0);
      z.push_back(z.back());
    }
    t.push_back(t0 + 1e-3);
    z.push_back(control::filled(level));
  }
  return SetpointProfile::from_samples(std::move(t), std::move(z), "staircase");
}

// kind < 0: no fault.
Outcome run_scenario(std::uint64_t seed, int kind, double rate_Hz = kRate_Hz,
                     const control::SemiClosedLoopParams& params = {}) {
  std::mt19937_64 rng(seed);
  SetpointProfile profile = staircase(rng);
  std::vector<FaultSpec> faults;
  if (kind >= 0) {
    FaultSpec f;
    f.kind = static_cast<FaultKind>(kind);
    f.time_s = std::uniform_real_distribution<double>(0.08, 0.2)(rng);
    f.channel = f.kind == FaultKind::kOverrunBurst
                    ? -1
                    : static_cast<int>(std::uniform_int_distribution<int>(0, 2)(rng));
    faults.push_back(f);
  }
  SimOptions so;
  so.seed = seed;
  so.rate_Hz = rate_Hz;
  SimBackend sim(so);
  SimulatedClock clock;
  FaultInjectingBackend daq(sim, clock, std::llround(1e9 / rate_Hz), faults, FaultInjectionParams{},
                            &sim);
  daq.configure();
  daq.activate();
  LoopConfig cfg;
  cfg.rate_Hz = rate_Hz;
  cfg.duration_s = kDuration_s;
  ControlLoop loop(cfg, params, SafetyLimits{}, daq, clock, std::move(profile));
  Outcome o;
  o.result = loop.run();
  daq.deactivate();
  o.injected_tick = daq.first_injected_tick();
  o.label = "seed " + std::to_string(seed) +
            (faults.empty() ? std::string(" no fault")
                            : std::string(" ") + to_string(faults[0].kind) + "@" +
                                  std::to_string(faults[0].time_s) + ":" +
                                  std::to_string(faults[0].channel + 1));
  return o;
}

void expect_outputs_safe(const Outcome& o) {
  EXPECT_LE(o.result.max_output_V, 10.0) << o.label;
  EXPECT_GE(o.result.min_output_V, 0.0) << o.label;
  EXPECT_LE(o.result.max_output_slew_V_per_ms, 1.5 + 1e-9) << o.label;
}

// The paper's gains re-expressed for 0.1 ms (kp 0.6, ki 0.02, kd 0.01), on the same staircases.
TEST(FaultCampaign, FaultFreeStaircasesAt10kHzNeverTrip) {
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const Outcome o = run_scenario(seed, -1, 10'000.0);
    EXPECT_FALSE(o.result.fault_detected)
        << o.label << ": " << to_string(o.result.fault.reason) << " at tick " << o.result.fault.tick
        << " channel " << o.result.fault.channel + 1;
    expect_outputs_safe(o);
  }
}

TEST(FaultCampaign, FaultFreeStaircasesNeverTrip) {
  for (std::uint64_t seed = 1; seed <= 60; ++seed) {
    const Outcome o = run_scenario(seed, -1);
    EXPECT_FALSE(o.result.fault_detected)
        << o.label << ": " << to_string(o.result.fault.reason) << " at tick " << o.result.fault.tick
        << " channel " << o.result.fault.channel + 1 << " value " << o.result.fault.value
        << " limit " << o.result.fault.limit;
    EXPECT_EQ(o.result.stop_reason, StopReason::kDuration) << o.label;
    expect_outputs_safe(o);
  }
}

TEST(FaultCampaign, EveryFaultIsCaughtWithinItsStatedLatencyAndOutputsStayInLimits) {
  constexpr int kPerKind = 150;  // 7 kinds x 150 = 1050 scenarios
  std::array<std::uint64_t, kFaultKinds> worst{};
  std::array<std::map<std::string, int>, kFaultKinds> reasons;
  for (int n = 0; n < kPerKind; ++n) {
    for (std::size_t k = 0; k < kFaultKinds; ++k) {
      const std::uint64_t seed = 1000 + static_cast<std::uint64_t>(n) * kFaultKinds + k;
      const Outcome o = run_scenario(seed, static_cast<int>(k));
      const Expectation& e = kExpected[k];
      expect_outputs_safe(o);
      ASSERT_NE(o.injected_tick, FaultInjectingBackend::kNotYet) << o.label;
      EXPECT_TRUE(o.result.fault_detected) << o.label << ": not detected";
      if (!o.result.fault_detected) {
        ++reasons[k]["UNDETECTED"];
        continue;
      }
      EXPECT_EQ(o.result.stop_reason, StopReason::kFault) << o.label;
      EXPECT_TRUE(e.reasons.count(o.result.fault.reason))
          << o.label << ": caught as " << to_string(o.result.fault.reason);
      ASSERT_GE(o.result.fault.tick, o.injected_tick)
          << o.label << ": " << to_string(o.result.fault.reason) << " before the fault";
      const std::uint64_t latency = o.result.fault.tick - o.injected_tick;
      EXPECT_LE(latency, e.max_latency_ticks)
          << o.label << ": caught as " << to_string(o.result.fault.reason) << " after " << latency
          << " ticks";
      worst[k] = std::max(worst[k], latency);
      ++reasons[k][to_string(o.result.fault.reason)];
    }
  }
  for (std::size_t k = 0; k < kFaultKinds; ++k) {
    std::string by;
    for (const auto& [reason, count] : reasons[k])
      by += " " + reason + " x" + std::to_string(count);
    std::printf("  %-15s worst latency %3llu ticks (stated %3llu);%s\n",
                to_string(static_cast<FaultKind>(k)), static_cast<unsigned long long>(worst[k]),
                static_cast<unsigned long long>(kExpected[k].max_latency_ticks), by.c_str());
  }
}

// After a long stall the twin once advanced every missed period, so a twin slower than real
// time made each tick longer than the last and never caught up; a read advances at most
// kMaxCatchUpPeriods.
TEST(SimBackendCatchUp, ALateTickAdvancesAtMostTheCatchUpLimit) {
  SimBackend sim(SimOptions{});
  sim.configure();
  sim.activate();
  Vec3 ai{};
  ASSERT_EQ(sim.read(CycleTime{0, 0, 1'000'000}, ai), DaqStatus::kOk);
  EXPECT_EQ(sim.twin().ticks(), 1u);
  ASSERT_EQ(sim.read(CycleTime{1, 5'000'000, 4'000'000}, ai), DaqStatus::kOk);  // 4 periods late
  EXPECT_EQ(sim.twin().ticks(), 5u);
  ASSERT_EQ(sim.read(CycleTime{2, 1'005'000'000, 1'000'000'000}, ai), DaqStatus::kOk);  // 1 s
  EXPECT_EQ(sim.twin().ticks(), 5u + SimBackend::kMaxCatchUpPeriods);
}

}  // namespace
}  // namespace piezoshift::runtime
