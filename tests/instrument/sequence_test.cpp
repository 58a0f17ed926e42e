// The measurement sequence through the shipping loop (owner mode, simulated clock, the twin as
// the DAQ backend), with a scripted camera whose behaviour each test chooses.
#include "piezoshift/instrument/sequence.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "piezoshift/config/project_config.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/runtime/loop_clock.hpp"
#include "piezoshift/runtime/sim_backend.hpp"
#include "scripted_camera.hpp"

namespace piezoshift::instrument {
namespace {

// The twin behind the loop every command ships, in owner mode on a simulated clock.
struct Rig {
  config::ProjectConfig config;
  runtime::SimBackend sim;
  runtime::SimulatedClock clock;
  runtime::ControlLoop loop;

  static runtime::SimOptions sim_options(const config::ProjectConfig& c) {
    runtime::SimOptions so;
    so.design = c.design;
    so.twin = c.twin;
    so.seed = 7;
    so.rate_Hz = 1.0 / c.twin.daq.sample_time_s;
    return so;
  }
  static runtime::LoopConfig loop_config(const config::ProjectConfig& c) {
    runtime::LoopConfig lc;
    lc.rate_Hz = 1.0 / c.twin.daq.sample_time_s;
    lc.duration_s = std::numeric_limits<double>::infinity();
    lc.owner_drives = true;
    return lc;
  }
  static control::SemiClosedLoopParams paper(const config::ProjectConfig& c) {
    control::SemiClosedLoopParams p;
    p.sample_time_s = c.twin.daq.sample_time_s;
    return p;
  }
  Rig()
      : sim(sim_options(config)),
        loop(loop_config(config), paper(config), runtime::SafetyLimits{}, sim, clock,
             runtime::SetpointProfile::step(0.0)) {
    sim.configure();
    sim.activate();
  }
  ~Rig() { sim.deactivate(); }
};

SequenceParams five_steps() {
  SequenceParams p;
  for (int k = 0; k < 5; ++k)
    p.steps_rad.push_back(k * std::numbers::pi / 2.0);
  return p;
}

TEST(SequenceTest, EachFrameIsExposedAfterSettlingAtItsCommandedPiston) {
  Rig rig;
  ScriptedCamera cam;
  camera::CameraSettings cs;
  cs.exposure_s = 0.002;
  cs.readout_s = 0.010;
  cam.configure(cs);
  const SequenceParams p = five_steps();
  const SequenceResult r = run_sequence(rig.loop, &rig.sim.twin(), cam, p);
  ASSERT_TRUE(r.validity.valid) << r.validity.reason;
  ASSERT_EQ(r.frames.size(), 5u);
  ASSERT_EQ(r.exposures.size(), 5u);
  for (std::size_t k = 0; k < 5; ++k) {
    const ExposureRecord& e = r.exposures[k];
    EXPECT_EQ(e.frame_id, k);
    EXPECT_NEAR(e.commanded_piston_nm, k * 632.8 / 8.0, 1e-9);
    EXPECT_GT(e.settled_time_s, e.move_time_s);
    EXPECT_GE(e.trigger_time_s, e.settled_time_s);
    EXPECT_NEAR(e.exposure_end_s - e.trigger_time_s, 0.002, 1e-9);
    // The true piston within 10 nm of the commanded one: the gauges, not the interferometer,
    // close this loop, and the paper's A and p are not this twin's calibration.
    EXPECT_NEAR(e.truth_piston_nm, e.commanded_piston_nm, 10.0) << k;
    // Settled on the 5 ms mean; over a 2-tick exposure the mean keeps the gauges' white noise,
    // about 1.5 nm rms a sample (docs/twin.md), so 1.1 nm rms: the band plus 3 sigma.
    EXPECT_LE(e.gauge_error_mean_nm, p.on_target.band_nm + 3.3) << k;
    // The camera saw the exposure's first instant and one pose per tick after it.
    ASSERT_EQ(cam.exposures[k].size(), 3u);
    EXPECT_NEAR(cam.exposures[k].front().time_s, e.trigger_time_s, 1e-12);
  }
  // A frame's readout (10 ms) overlaps the next move and settle, so the floor counts each.
  EXPECT_NEAR(r.floor_s, 5 * (0.005 + 0.002 + 0.010), 1e-9);
  EXPECT_GE(r.loop_time_s, 5 * (0.005 + 0.002));
  EXPECT_EQ(r.overruns, 0u);  // a simulated clock is never late
}

TEST(SequenceTest, AveragesRepeatTheWholeSequence) {
  Rig rig;
  ScriptedCamera cam;
  cam.configure({});
  SequenceParams p = five_steps();
  p.averages = 3;
  const SequenceResult r = run_sequence(rig.loop, &rig.sim.twin(), cam, p);
  ASSERT_TRUE(r.validity.valid) << r.validity.reason;
  ASSERT_EQ(r.exposures.size(), 15u);
  EXPECT_EQ(r.exposures[14].average, 2);
  EXPECT_EQ(r.exposures[14].frame, 4);
  EXPECT_NEAR(r.exposures[10].truth_piston_nm, 0.0, 10.0);  // back to the base for average 3
}

TEST(SequenceTest, ALostFrameEndsTheSequenceAsNotValid) {
  Rig rig;
  ScriptedCamera cam;
  cam.configure({});
  cam.lose_frame = 2;
  const SequenceResult r = run_sequence(rig.loop, &rig.sim.twin(), cam, five_steps());
  EXPECT_FALSE(r.validity.valid);
  EXPECT_NE(r.validity.reason.find("lost frame 2"), std::string::npos) << r.validity.reason;
  EXPECT_EQ(r.frames.size(), 2u);  // never a silently short sequence: the two before it only
  EXPECT_TRUE(rig.loop.result().stop_reason == runtime::StopReason::kDuration);
}

TEST(SequenceTest, AStageThatCannotSettleIsAFailureNotAFrame) {
  Rig rig;
  ScriptedCamera cam;
  cam.configure({});
  SequenceParams p = five_steps();
  p.on_target.band_nm = 1e-6;  // far below the gauges' noise: never met
  p.on_target.timeout_s = 0.05;
  const SequenceResult r = run_sequence(rig.loop, &rig.sim.twin(), cam, p);
  EXPECT_FALSE(r.validity.valid);
  EXPECT_NE(r.validity.reason.find("did not settle"), std::string::npos) << r.validity.reason;
  EXPECT_TRUE(r.frames.empty());
}

TEST(SequenceTest, ACameraThatTakesNoTriggerTimesOut) {
  Rig rig;
  ScriptedCamera cam;
  cam.configure({});
  cam.refuse = true;
  SequenceParams p = five_steps();
  p.frame_timeout_s = 0.1;
  const SequenceResult r = run_sequence(rig.loop, &rig.sim.twin(), cam, p);
  EXPECT_FALSE(r.validity.valid);
  EXPECT_NE(r.validity.reason.find("took no trigger"), std::string::npos) << r.validity.reason;
  EXPECT_NE(r.validity.reason.find("refusing"), std::string::npos) << r.validity.reason;
}

TEST(SequenceTest, ParametersOutOfRangeAreRefusedNamingTheValue) {
  SequenceParams p = five_steps();
  EXPECT_EQ(sequence_problem(p), "");
  p.steps_rad = {0.0, 1.0};
  EXPECT_NE(sequence_problem(p).find("3 to 64"), std::string::npos);
  p.steps_rad = {0.5, 1.0, 2.0};
  EXPECT_NE(sequence_problem(p).find("step 0 = 0.5"), std::string::npos);
  p.steps_rad = {0.0, std::nan(""), 2.0};
  EXPECT_NE(sequence_problem(p).find("step 1"), std::string::npos);
  p = five_steps();
  p.averages = 0;
  EXPECT_NE(sequence_problem(p).find("0 averages"), std::string::npos);
  Rig rig;
  ScriptedCamera cam;
  EXPECT_THROW(run_sequence(rig.loop, &rig.sim.twin(), cam, p), core::InputError);
}

TEST(SequenceTest, CommandedStepsFollowTheAlgorithmAndRefuseWhatItCannotTake) {
  const std::vector<double> h5 = commanded_steps(psi::Algorithm::kHariharan5, {}, "--steps-rad");
  ASSERT_EQ(h5.size(), 5u);
  EXPECT_NEAR(h5[4], 2.0 * std::numbers::pi, 1e-12);
  const std::vector<double> f13 = commanded_steps(psi::Algorithm::kFrame13, {}, "--steps-rad");
  ASSERT_EQ(f13.size(), 13u);
  EXPECT_NEAR(f13[1], std::numbers::pi / 4.0, 1e-12);  // the 13-frame's pi/4
  EXPECT_EQ(commanded_steps(psi::Algorithm::kAia, {}, "x").size(), 5u);
  EXPECT_EQ(commanded_steps(psi::Algorithm::kAia, {0.0, 1.4, 3.3, 4.6}, "x")[2], 3.3);
  EXPECT_THROW(commanded_steps(psi::Algorithm::kHariharan5, {0.0, 1.0, 2.0}, "x"),
               core::InputError);
  EXPECT_THROW(commanded_steps(psi::Algorithm::kFourStep, {}, "x").at(4), std::out_of_range);
}

TEST(SequenceTest, TheSequencesTopIsHeldToTheCalibratedTravel) {
  SequenceParams p = five_steps();
  p.base_um = 11.0;  // the top frame is 2 pi: 316.4 nm above the base
  EXPECT_EQ(travel_problem(p, std::nullopt, "none"), "");
  EXPECT_EQ(travel_problem(p, 11.32, "cal.toml"), "");
  const std::string why = travel_problem(p, 11.3, "cal.toml");
  EXPECT_NE(why.find("11.3164 um"), std::string::npos) << why;
  EXPECT_NE(why.find("cal.toml"), std::string::npos) << why;
}

}  // namespace
}  // namespace piezoshift::instrument
