// The sequence driven from a loop's samples (serve's dashboard), on a synthetic loop: Z_d takes a
// move two ticks after it is sent (the host link's latency), the gauges' tracking error decays
// from the step with time constant tau, and the plate follows Z_d with the same lag. Plus the
// settle window both drivers share.
#include "piezoshift/instrument/sample_sequence.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <optional>
#include <string>

#include "piezoshift/instrument/settle_window.hpp"
#include "scripted_camera.hpp"

namespace piezoshift::instrument {
namespace {

constexpr double kPeriod_s = 1e-3;

struct SyntheticLoop {
  double tau_s = 0.004;  // the gauges' error decays e^(-t/tau) after a step
  double zd_um = 0.0;    // in force
  double plate_um = 0.0;
  std::optional<double> pending_um;
  int pending_ticks = 0;
  std::uint64_t tick = 0;
  std::string refuse;  // a move refused with this

  std::string move(double z_um) {
    if (!refuse.empty())
      return refuse;
    pending_um = z_um;
    pending_ticks = 2;
    return {};
  }
  LoopSample step() {
    ++tick;
    if (pending_um && --pending_ticks == 0) {
      zd_um = *pending_um;
      pending_um.reset();
    }
    // The plate and the gauges approach Z_d exponentially.
    plate_um += (zd_um - plate_um) * (1.0 - std::exp(-kPeriod_s / tau_s));
    LoopSample s;
    s.tick = tick;
    s.t_s = static_cast<double>(tick) * kPeriod_s;
    const double e_nm = 1000.0 * (zd_um - plate_um);
    s.gauge_error_nm = {e_nm, e_nm, e_nm};
    s.zd_um = {zd_um, zd_um, zd_um};
    s.closed_loop = true;
    s.has_truth = true;
    s.pose = {s.t_s, 1000.0 * plate_um, 0.0, 0.0};
    return s;
  }
};

SequenceParams five_steps() {
  SequenceParams p;
  for (int k = 0; k < 5; ++k)
    p.steps_rad.push_back(k * std::numbers::pi / 2.0);
  return p;
}

// Runs the sequence for at most max_ticks of the synthetic loop; `during` may change it.
SequenceResult run(SampleSequence& seq, SyntheticLoop& loop, int max_ticks = 20000,
                   const std::function<void(SyntheticLoop&, const SampleSequence&)>& during = {}) {
  for (int k = 0; k < max_ticks && !seq.done(); ++k) {
    seq.feed(loop.step());
    seq.poll();
    if (during)
      during(loop, seq);
  }
  EXPECT_TRUE(seq.done());
  return seq.take();
}

TEST(SampleSequenceTest, EachFrameIsExposedAfterSettlingAtItsCommandedPiston) {
  ScriptedCamera cam;
  cam.configure({});
  SyntheticLoop loop;
  const SequenceParams p = five_steps();
  SampleSequence seq(cam, p, kPeriod_s, [&](double z) { return loop.move(z); });
  const SequenceResult r = run(seq, loop);
  ASSERT_TRUE(r.validity.valid) << r.validity.reason;
  ASSERT_EQ(r.frames.size(), 5u);
  ASSERT_EQ(r.exposures.size(), 5u);
  for (std::size_t k = 0; k < 5; ++k) {
    const ExposureRecord& e = r.exposures[k];
    const double piston_nm = p.steps_rad[k] * p.wavelength_nm / (4.0 * std::numbers::pi);
    EXPECT_NEAR(e.commanded_piston_nm, piston_nm, 1e-9);
    // Settled: the 5-tick mean error within 2 nm, so the plate within a few nm of the step
    // (the error decays 22 % a tick: its mean over the hold lags the last value).
    EXPECT_NEAR(e.truth_piston_nm, piston_nm, 2.0) << "frame " << k;
    EXPECT_LT(e.gauge_error_mean_nm, 2.0) << "frame " << k;
    // In order: moved, applied two ticks later (frame 0 stays at the base: at once), settled
    // after the hold's 5 ticks, exposed from there.
    const double lag_s = k == 0 ? 0.0 : 2 * kPeriod_s;
    EXPECT_GE(e.settled_time_s, e.move_time_s + lag_s + p.on_target.hold_s - 1e-9) << k;
    EXPECT_GE(e.trigger_time_s, e.settled_time_s);
    EXPECT_NEAR(e.exposure_end_s - e.trigger_time_s, cam.settings().exposure_s, 1e-9);
    EXPECT_EQ(e.frame_id, k);
  }
}

TEST(SampleSequenceTest, AnotherClientsMoveEndsItWithThatReason) {
  ScriptedCamera cam;
  cam.configure({});
  SyntheticLoop loop;
  SampleSequence seq(cam, five_steps(), kPeriod_s, [&](double z) { return loop.move(z); });
  const SequenceResult r = run(seq, loop, 20000, [](SyntheticLoop& l, const SampleSequence& s) {
    if (s.frames_taken() == 2 && !l.pending_um)
      l.zd_um = 3.0;  // another client's MOV Z 3
  });
  EXPECT_FALSE(r.validity.valid);
  EXPECT_NE(r.validity.reason.find("another client's move"), std::string::npos)
      << r.validity.reason;
}

// The same move while the sequence's own is on its way: seen between ours and the loop (the
// sequence read its samples late), or made after ours so that ours never shows. Either is
// another client's, not "not applied yet" (which before ended valid, or at the apply timeout
// with another reason).
TEST(SampleSequenceTest, AnotherClientsMoveWhileOursIsPendingEndsItWithThatReason) {
  for (const bool after_ours : {false, true}) {
    ScriptedCamera cam;
    cam.configure({});
    SyntheticLoop loop;
    SampleSequence seq(cam, five_steps(), kPeriod_s, [&](double z) { return loop.move(z); });
    const SequenceResult r = run(seq, loop, 20000, [&](SyntheticLoop& l, const SampleSequence& s) {
      if (s.frames_taken() == 2 && l.pending_um && l.pending_ticks == 2) {
        if (after_ours)
          l.pending_um = 3.0;  // replaces ours before the loop applies it
        else
          l.zd_um = 3.0;  // in force one tick before ours
      }
    });
    EXPECT_FALSE(r.validity.valid) << after_ours;
    EXPECT_EQ(r.exposures.size(), 2u) << after_ours;
    EXPECT_NE(r.validity.reason.find("another client's move"), std::string::npos)
        << r.validity.reason;
  }
}

TEST(SampleSequenceTest, ARefusedMoveEndsItNamingTheRefusal) {
  ScriptedCamera cam;
  cam.configure({});
  SyntheticLoop loop;
  loop.refuse = "`MOV Z 5 U 0 V 0`: GCS error 73";
  SampleSequence seq(cam, five_steps(), kPeriod_s, [&](double z) { return loop.move(z); });
  const SequenceResult r = run(seq, loop);
  EXPECT_FALSE(r.validity.valid);
  EXPECT_NE(r.validity.reason.find("GCS error 73"), std::string::npos) << r.validity.reason;
  EXPECT_TRUE(r.frames.empty());
}

TEST(SampleSequenceTest, AStageThatDoesNotSettleIsAFailureNotAFrame) {
  ScriptedCamera cam;
  cam.configure({});
  SyntheticLoop loop;
  loop.tau_s = 100.0;  // far slower than the 1 s timeout
  SampleSequence seq(cam, five_steps(), kPeriod_s, [&](double z) { return loop.move(z); });
  const SequenceResult r = run(seq, loop);
  EXPECT_FALSE(r.validity.valid);
  EXPECT_NE(r.validity.reason.find("did not settle"), std::string::npos) << r.validity.reason;
  EXPECT_TRUE(r.exposures.empty());
}

TEST(SampleSequenceTest, ALatchedFaultIsNotClearedByAMeasurement) {
  ScriptedCamera cam;
  cam.configure({});
  SyntheticLoop loop;
  int moves = 0;
  SampleSequence seq(cam, five_steps(), kPeriod_s, [&](double z) {
    ++moves;
    return loop.move(z);
  });
  LoopSample s = loop.step();
  s.faulted = true;
  s.fault = "tracking";
  seq.feed(s);
  ASSERT_TRUE(seq.done());
  const SequenceResult r = seq.take();
  EXPECT_FALSE(r.validity.valid);
  EXPECT_NE(r.validity.reason.find("tracking latched: clear it"), std::string::npos)
      << r.validity.reason;
  EXPECT_EQ(moves, 0);  // no SVO, no MOV sent
}

TEST(SettleWindowTest, SettledOnlyOnceTheWindowsMeanIsWithinTheBandOnEveryChannel) {
  psi::OnTarget c;
  c.band_nm = 2.0;
  c.hold_s = 0.005;
  SettleWindow w(c, 1e-3);
  EXPECT_EQ(w.length(), 5u);
  for (int k = 0; k < 4; ++k)
    EXPECT_FALSE(w.add({1.0, -1.0, 0.5}));  // within the band, the window not full yet
  EXPECT_TRUE(w.add({1.0, -1.0, 0.5}));
  EXPECT_DOUBLE_EQ(w.worst_mean_nm(), 1.0);
  // One channel's mean beyond the band: (4 x 0.5 + 13) / 5 = 3 nm.
  EXPECT_FALSE(w.add({1.0, -1.0, 13.0}));
  EXPECT_DOUBLE_EQ(w.worst_mean_nm(), 3.0);
  w.reset();
  EXPECT_FALSE(w.add({0.0, 0.0, 0.0}));  // after a reset the window fills again
}

}  // namespace
}  // namespace piezoshift::instrument
