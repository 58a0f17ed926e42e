// ControlLoop in host mode (`piezoshift serve`): set-points and servo state from HostCommands,
// one HostSample back per tick. On the closed-form FakeBackend plant and a simulated clock.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "allocation_counter.hpp"
#include "fake_backend.hpp"
#include "piezoshift/runtime/control_loop.hpp"
#include "piezoshift/runtime/sim_backend.hpp"

namespace piezoshift::runtime {
namespace {

using testing::FakeBackend;

struct HostRun {
  LoopResult result;
  std::vector<HostSample> samples;
};

// Runs duration_s in host mode with the commands queued before the start (applied at tick 0)
// and, optionally, one more pushed by the plant at tick `later_at`.
struct Later {
  HostLink* link = nullptr;
  HostCommand command{};
};
void push_later(void* context) {
  auto* l = static_cast<Later*>(context);
  l->link->commands.try_push(l->command);
}

HostRun run_host(const std::vector<HostCommand>& commands, double duration_s,
                 const HostCommand* later = nullptr, std::uint64_t later_at = 0) {
  FakeBackend daq;
  daq.configure();
  daq.activate();
  SimulatedClock clock;
  HostLink link;
  Later l{&link, later != nullptr ? *later : HostCommand{}};
  if (later != nullptr) {
    daq.on_tick = push_later;
    daq.on_tick_context = &l;
    daq.on_tick_at = later_at;
  }
  for (const HostCommand& c : commands)
    EXPECT_TRUE(link.commands.try_push(c));
  LoopConfig cfg;
  cfg.rate_Hz = 1000.0;
  cfg.duration_s = duration_s;
  cfg.host = &link;
  ControlLoop loop(cfg, control::SemiClosedLoopParams{}, SafetyLimits{}, daq, clock,
                   SetpointProfile::step(0.0));
  HostRun r;
  r.result = loop.run();
  for (HostSample s{}; link.samples.try_pop(s);)
    r.samples.push_back(s);
  return r;
}

HostCommand command(HostCommand::Kind kind, std::uint64_t sequence, Vec3 zd = {}, Vec3 ao = {}) {
  HostCommand c;
  c.kind = kind;
  c.sequence = sequence;
  c.zd_um = zd;
  c.ao_V = ao;
  return c;
}

HostCommand actuators_command(std::uint64_t sequence, Vec3 s_um) {
  HostCommand c = command(HostCommand::Kind::kActuators, sequence);
  c.actuator_target_um = s_um;
  return c;
}

TEST(HostMode, StartsWithTheServoOffAtZeroVoltsAndSendsOneSamplePerTick) {
  const HostRun r = run_host({}, 0.1);
  EXPECT_FALSE(r.result.fault_detected);
  ASSERT_EQ(r.samples.size(), r.result.ticks);
  for (std::size_t k = 0; k < r.samples.size(); ++k) {
    EXPECT_EQ(r.samples[k].tick, k);
    EXPECT_EQ(r.samples[k].closed_loop, 0);
    EXPECT_EQ(r.samples[k].applied_sequence, 0u);
    EXPECT_EQ(r.samples[k].ao_V, Vec3{});
  }
  EXPECT_EQ(r.result.host_samples_dropped, 0u);
}

TEST(HostMode, ServoOnThenMoveTracksTheFeedforwardTargets) {
  // A move while the servo is off is ignored; the servo-on command's Z_d is then the target.
  const HostRun r = run_host({command(HostCommand::Kind::kMoveTo, 1, control::filled(3.0)),
                              command(HostCommand::Kind::kServoOn, 2, control::filled(0.0)),
                              command(HostCommand::Kind::kMoveTo, 3, control::filled(8.0))},
                             0.3);
  EXPECT_FALSE(r.result.fault_detected) << to_string(r.result.fault.reason);
  EXPECT_EQ(r.result.host_commands_applied, 3u);
  const HostSample& s = r.samples.at(299);  // the last tick before the ramp to 0 V
  EXPECT_EQ(s.applied_sequence, 3u);
  EXPECT_EQ(s.closed_loop, 1);
  EXPECT_EQ(s.zd_um, control::filled(8.0));
  const Vec3 target = control::SemiClosedLoopController{}.actuator_targets(control::filled(8.0));
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(s.target_um[i], target[i], 1e-12);
    EXPECT_NEAR(s.sgs_V[i] * 1.6, target[i], 0.005) << i;  // the inner loop sits on S
  }
}

TEST(HostMode, OpenLoopVoltsGoOutThroughTheSlewLimitAndTenVoltsIsNoFault) {
  const HostRun r =
      run_host({command(HostCommand::Kind::kOpenLoop, 1, {}, control::filled(10.0))}, 0.2);
  EXPECT_FALSE(r.result.fault_detected) << to_string(r.result.fault.reason);
  EXPECT_LE(r.result.max_output_slew_V_per_ms, 1.5 + 1e-9);
  // 1.5 V per tick from tick 0: 10 V from tick 6 on, held to the end (no saturation rule).
  EXPECT_NEAR(r.samples.at(5).ao_V[0], 9.0, 1e-12);
  EXPECT_EQ(r.samples.at(6).ao_V[0], 10.0);
  EXPECT_EQ(r.samples.at(199).ao_V, control::filled(10.0));
  EXPECT_EQ(r.samples.at(199).closed_loop, 0);
}

TEST(HostMode, ServoOffHoldsTheAppliedVolts) {
  // Closed loop to 8 um, servo off at tick 150: the outputs stay where they were.
  const HostCommand off = command(HostCommand::Kind::kServoOff, 3);
  const HostRun r = run_host({command(HostCommand::Kind::kServoOn, 1, control::filled(0.0)),
                              command(HostCommand::Kind::kMoveTo, 2, control::filled(8.0))},
                             0.3, &off, 150);
  EXPECT_FALSE(r.result.fault_detected) << to_string(r.result.fault.reason);
  const HostSample& before = r.samples.at(149);
  const HostSample& after = r.samples.at(299);
  EXPECT_EQ(before.closed_loop, 1);
  EXPECT_EQ(after.closed_loop, 0);
  EXPECT_EQ(after.applied_sequence, 3u);
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_NEAR(after.ao_V[i], before.ao_V[i], 1e-3) << i;
}

TEST(HostMode, ActuatorTargetsHoldTheSgsOnSAndAreNoZd) {
  // The guided calibration's stage 2 (rig/loop_rig.hpp): the PIDs alone on S.
  const Vec3 s_um{2.0, 9.0, 2.0};
  const HostRun r = run_host({actuators_command(1, s_um)}, 0.3);
  EXPECT_FALSE(r.result.fault_detected) << to_string(r.result.fault.reason);
  const HostSample& h = r.samples.at(299);
  EXPECT_EQ(h.closed_loop, 1);
  EXPECT_EQ(h.actuators, 1);
  EXPECT_EQ(h.zd_um, Vec3{});  // S is not a Z_d
  EXPECT_EQ(h.target_um, s_um);
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_NEAR(h.sgs_V[i] * 1.6, s_um[i], 0.005) << i;  // FakeBackend: sgs_V = x / 1.6 um/V
}

// Holds the PIDs on S = 5 um for 0.6 s; at tick 300 a kConfigure arrives, with `params` pushed
// before it unless it is null.
struct SwitchRun {
  LoopResult result;
  std::vector<HostSample> samples;
  control::SemiClosedLoopParams in_force;  //!< the controller's parameters at the end
  Vec3 targets_at_2um{};                   //!< its actuator_targets(Z_d = 2 um)
};

SwitchRun run_switch(const control::SemiClosedLoopParams* params) {
  FakeBackend daq;
  daq.configure();
  daq.activate();
  SimulatedClock clock;
  HostLink link;
  EXPECT_TRUE(link.commands.try_push(actuators_command(1, control::filled(5.0))));
  LoopConfig cfg;
  cfg.rate_Hz = 1000.0;
  cfg.duration_s = 0.6;
  cfg.host = &link;
  ControlLoop loop(cfg, control::SemiClosedLoopParams{}, SafetyLimits{}, daq, clock,
                   SetpointProfile::step(0.0));
  struct Switch {
    HostLink* link;
    const control::SemiClosedLoopParams* params;
  } sw{&link, params};
  daq.on_tick = [](void* c) {
    auto* s = static_cast<Switch*>(c);
    if (s->params != nullptr)
      s->link->params.try_push(*s->params);
    s->link->commands.try_push(command(HostCommand::Kind::kConfigure, 2));
  };
  daq.on_tick_context = &sw;
  daq.on_tick_at = 299;
  SwitchRun r;
  r.result = loop.run();
  for (HostSample h{}; link.samples.try_pop(h);)
    r.samples.push_back(h);
  r.in_force = loop.controller().params();
  r.targets_at_2um = loop.controller().actuator_targets(control::filled(2.0));
  return r;
}

TEST(HostMode, NewParametersAreAppliedBetweenTwoTicksBumplessly) {
  // On S = 5 um, then a controller with a matrix A that doubles the targets and other gains: the
  // output does not jump at the switch (the PIDs restart from the command held), the inner loops
  // stay on S, and the new controller asks S = A Z_d = 4 um for Z_d = 2 um.
  control::SemiClosedLoopParams p{};
  p.matrix.a = {{{2.0, 0.0, 0.0}, {0.0, 2.0, 0.0}, {0.0, 0.0, 2.0}}};
  p.polynomial = control::CubicPolynomial::identity();
  p.gains.kp = 0.3;
  const SwitchRun r = run_switch(&p);
  EXPECT_FALSE(r.result.fault_detected) << to_string(r.result.fault.reason);
  const HostSample& before = r.samples.at(299);
  const HostSample& at = r.samples.at(300);
  EXPECT_EQ(before.applied_sequence, 1u);
  EXPECT_EQ(at.applied_sequence, 2u);
  EXPECT_EQ(at.configure_problem, 0);
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_NEAR(at.ao_V[i], before.ao_V[i], 1e-3) << i;
  EXPECT_EQ(r.in_force.gains.kp, 0.3);
  EXPECT_NEAR(r.in_force.sample_time_s, 1e-3, 1e-15);  // the loop's, kept
  EXPECT_EQ(r.targets_at_2um, control::filled(4.0));
  const HostSample& end = r.samples.at(599);
  EXPECT_EQ(end.actuators, 1);
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_NEAR(end.sgs_V[i] * 1.6, 5.0, 0.005) << i;
}

// Until this check, ControlCycle::configure threw std::invalid_argument for an improved
// controller at another rate, inside the noexcept loop: std::terminate with the DACs holding.
// Now the loop refuses the set, says why in every later sample, and runs on unchanged.
void expect_refused_and_running(const SwitchRun& r, control::ParamsProblem problem) {
  EXPECT_FALSE(r.result.fault_detected) << to_string(r.result.fault.reason);
  // The loop ran to its end (0.6 s, then its ramp down).
  ASSERT_EQ(r.samples.size(), r.result.ticks);
  ASSERT_GE(r.samples.size(), 600u);
  EXPECT_EQ(r.samples.at(299).configure_problem, 0);
  for (std::size_t k = 300; k < r.samples.size(); ++k) {
    ASSERT_EQ(r.samples[k].applied_sequence, 2u) << k;
    ASSERT_EQ(r.samples[k].configure_problem, static_cast<std::uint8_t>(problem)) << k;
  }
  EXPECT_EQ(r.in_force.kind, control::ControllerKind::kPaper);  // the old controller, unchanged
  EXPECT_EQ(r.in_force.gains.kp, control::SemiClosedLoopParams{}.gains.kp);
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_NEAR(r.samples.at(599).sgs_V[i] * 1.6, 5.0, 0.005) << i;  // still holding S
}

TEST(HostMode, AnImprovedControllerAtAnotherRateIsRefusedAndTheLoopRunsOn) {
  control::SemiClosedLoopParams p{};
  p.kind = control::ControllerKind::kImproved;
  p.improved.sample_time_s = 1e-4;  // designed for 10 kHz; the loop runs at 1 kHz
  expect_refused_and_running(run_switch(&p), control::ParamsProblem::kImprovedRate);
}

TEST(HostMode, ANonFiniteGainIsRefusedAndTheLoopRunsOn) {
  control::SemiClosedLoopParams p{};
  p.gains.ki = std::numeric_limits<double>::quiet_NaN();
  expect_refused_and_running(run_switch(&p), control::ParamsProblem::kNotFinite);
}

// The scaling is the wiring the supervisor was set up with; a set that changes it is refused.
TEST(HostMode, AnotherSignalScalingIsRefusedAndTheLoopRunsOn) {
  control::SemiClosedLoopParams p{};
  p.scaling[0].drive_V_per_um = 0.5;
  expect_refused_and_running(run_switch(&p), control::ParamsProblem::kScaling);
}

TEST(HostMode, AConfigureCommandWithoutAParameterSetIsRefused) {
  expect_refused_and_running(run_switch(nullptr), control::ParamsProblem::kAbsent);
}

HostCommand wave_start(std::uint64_t sequence, const double* values, std::uint32_t length,
                       std::uint32_t rate, std::uint32_t cycles, double reference) {
  HostCommand c;
  c.kind = HostCommand::Kind::kWave;
  c.sequence = sequence;
  c.wave.action = WaveCommand::Action::kStart;
  c.wave.generator = 0;
  c.wave.values = values;
  c.wave.length = length;
  c.wave.rate = rate;
  c.wave.cycles = cycles;
  c.wave.points_per_unit = Vec3{1.0, 0.5, 0.25};
  c.wave.reference = reference;
  return c;
}

TEST(HostMode, AWaveTablePlaysOnePointEveryRateTicksThenHoldsItsLastPoint) {
  // 10 points, 2 ticks each, one cycle: ticks 0..19 play them (the start is applied at tick 0,
  // before the set-point of that tick), from tick 20 on the set-point holds the last point.
  std::vector<double> table(10);
  for (std::size_t i = 0; i < table.size(); ++i)
    table[i] = 2.0 + 0.1 * static_cast<double>(i);
  const HostRun r = run_host({command(HostCommand::Kind::kServoOn, 1, control::filled(2.0)),
                              wave_start(2, table.data(), 10, 2, 1, 2.0)},
                             0.05);
  EXPECT_FALSE(r.result.fault_detected) << to_string(r.result.fault.reason);
  ASSERT_GE(r.samples.size(), 30u);
  for (std::size_t k = 0; k < 30; ++k) {
    const double w = table[std::min<std::size_t>(k / 2, 9)] - 2.0;
    EXPECT_DOUBLE_EQ(r.samples[k].zd_um[0], 2.0 + 1.0 * w) << k;
    EXPECT_DOUBLE_EQ(r.samples[k].zd_um[1], 2.0 + 0.5 * w) << k;
    EXPECT_DOUBLE_EQ(r.samples[k].zd_um[2], 2.0 + 0.25 * w) << k;
    EXPECT_EQ(r.samples[k].wave_running, k < 19 ? 1 : 0) << k;  // done with the 20th tick
  }
}

TEST(HostMode, AWaveStopsWhereItIsOnAStopAndWhenTheServoGoesOff) {
  std::vector<double> table{1.0, 2.0, 3.0, 4.0};
  HostCommand stop{};
  stop.kind = HostCommand::Kind::kWave;
  stop.sequence = 3;
  stop.wave.action = WaveCommand::Action::kStop;
  // Endless (cycles 0); the stop, pushed during tick 6, is applied at tick 7, which then plays
  // no point: the set-point keeps tick 6's value, table[6 % 4] = 3.
  const HostCommand start = wave_start(2, table.data(), 4, 1, 0, 0.0);
  const HostRun r = run_host({command(HostCommand::Kind::kServoOn, 1, control::filled(0.0)), start},
                             0.02, &stop, 6);
  ASSERT_GE(r.samples.size(), 10u);
  EXPECT_DOUBLE_EQ(r.samples[5].zd_um[0], 2.0);
  EXPECT_DOUBLE_EQ(r.samples[6].zd_um[0], 3.0);
  EXPECT_EQ(r.samples[6].wave_running, 1);
  for (std::size_t k = 7; k < 10; ++k) {
    EXPECT_DOUBLE_EQ(r.samples[k].zd_um[0], 3.0) << k;
    EXPECT_EQ(r.samples[k].wave_running, 0) << k;
  }
  // Servo off stops it too.
  HostCommand off = command(HostCommand::Kind::kServoOff, 3);
  const HostRun o = run_host({command(HostCommand::Kind::kServoOn, 1, control::filled(0.0)), start},
                             0.02, &off, 6);
  EXPECT_EQ(o.samples[6].wave_running, 1);
  EXPECT_EQ(o.samples[7].wave_running, 0);
}

TEST(HostMode, ARestartedWaveKeepsTheReferenceItsSetPointHolds) {
  // The host's target stays the first start's reference while the generator runs, so a restart
  // (whose own reference is ignored) plays the new table on the same base.
  std::vector<double> first{1.0, 2.0};
  std::vector<double> second{5.0};
  const HostCommand start = wave_start(2, first.data(), 2, 1, 0, 0.0);
  const HostCommand restart = wave_start(3, second.data(), 1, 1, 0, 99.0);
  const HostRun r = run_host({command(HostCommand::Kind::kServoOn, 1, control::filled(0.0)), start},
                             0.02, &restart, 3);
  ASSERT_GE(r.samples.size(), 8u);
  EXPECT_DOUBLE_EQ(r.samples[3].zd_um[0], 2.0);
  for (std::size_t k = 4; k < 8; ++k)
    EXPECT_DOUBLE_EQ(r.samples[k].zd_um[0], 5.0) << k;
}

TEST(HostMode, CommandsAndSamplesMakeNoHeapAllocation) {
  FakeBackend daq;
  daq.configure();
  daq.activate();
  SimulatedClock clock;
  HostLink link;
  const std::vector<HostCommand> commands{
      command(HostCommand::Kind::kServoOn, 1),
      command(HostCommand::Kind::kMoveTo, 2, Vec3{3, 4, 5}),
      command(HostCommand::Kind::kServoOff, 3),
      command(HostCommand::Kind::kOpenLoop, 4, {}, Vec3{2, 2, 2}),
      actuators_command(5, Vec3{1, 1, 1}),
      command(HostCommand::Kind::kConfigure, 6)};
  for (const HostCommand& c : commands)
    ASSERT_TRUE(link.commands.try_push(c));
  ASSERT_TRUE(link.params.try_push(control::SemiClosedLoopParams{}));
  LoopConfig cfg;
  cfg.rate_Hz = 10'000.0;
  cfg.duration_s = 0.6;  // 6000 ticks: more than the sample ring holds
  cfg.host = &link;
  ControlLoop loop(cfg, control::SemiClosedLoopParams{}, SafetyLimits{}, daq, clock,
                   SetpointProfile::step(0.0));
  testing::AllocationCounter counter;
  const LoopResult r = loop.run();
  EXPECT_EQ(counter.stop(), 0);
  EXPECT_EQ(r.host_commands_applied, 6u);
  EXPECT_EQ(r.host_samples_dropped, r.ticks - HostLink::kSampleCapacity)
      << "a full ring drops, never blocks";
}

// The twin's cavity drift reaches serve's samples (the dashboard camera renders the fringes from
// them): each sample's fringe_drift_nm is the twin's d_c at that tick when twin.cavity.in_fringes,
// and 0 otherwise (as on hardware).
TEST(HostMode, TheTwinsCavityDriftReachesEverySampleWhenItIsInTheFringes) {
  for (const bool in_fringes : {true, false}) {
    SimOptions o;
    o.twin.cavity.in_fringes = in_fringes;
    SimBackend sim(o);
    sim.configure();
    sim.activate();
    SimulatedClock clock;
    HostLink link;
    LoopConfig cfg;
    cfg.rate_Hz = 1000.0;
    cfg.duration_s = 0.2;
    cfg.host = &link;
    ControlLoop loop(cfg, control::SemiClosedLoopParams{}, SafetyLimits{}, sim, clock,
                     SetpointProfile::step(0.0));
    loop.start();
    double worst_nm = 0.0, largest_nm = 0.0;
    for (int k = 0; k < 200; ++k) {
      ASSERT_TRUE(loop.tick());
      HostSample s{};
      ASSERT_TRUE(link.samples.try_pop(s));
      const double d_c_nm = in_fringes ? sim.twin().truth().cavity_drift_nm : 0.0;
      worst_nm = std::max(worst_nm, std::fabs(s.fringe_drift_nm - d_c_nm));
      largest_nm = std::max(largest_nm, std::fabs(s.fringe_drift_nm));
    }
    EXPECT_LT(worst_nm, 1e-9) << in_fringes;  // the plate's piston cancels to rounding
    if (in_fringes)
      EXPECT_GT(largest_nm, 0.0);  // the air and the mount move from the first tick
    else
      EXPECT_EQ(largest_nm, 0.0);
  }
}

}  // namespace
}  // namespace piezoshift::runtime
