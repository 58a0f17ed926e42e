// The fringe lock's integral action against its closed forms, its limits, and its fallback when
// the fringes go: held, without a jump, and locked again from there.
#include "piezoshift/control/fringe_lock.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string_view>

namespace piezoshift::control {
namespace {

// The plant as the lock sees it: the cavity's path is the plate's correction plus a drift d,
// the correction seen by the next frame (one frame of delay).
struct Cavity {
  FringeAxes drift{};
  FringeAxes measure(const FringeAxes& c) const {
    return {c[0] + drift[0], c[1] + drift[1], c[2] + drift[2]};
  }
};

TEST(FringeLock, AnOffsetDecaysAsOneMinusGainToTheNthPower) {
  FringeLockParams p;
  p.gain_per_frame = 0.3;
  FringeLock lock(p);
  lock.start({0.0, 0.0, 0.0});
  const Cavity cav{{40.0, -2.0, 3.0}};  // within max_step at g = 0.3: the linear regime
  for (int n = 1; n <= 12; ++n) {
    lock.update(cav.measure(lock.correction()), true);
    const FringeAxes e = cav.measure(lock.correction());
    for (std::size_t a = 0; a < 3; ++a)
      EXPECT_NEAR(e[a], cav.drift[a] * std::pow(0.7, n), 1e-12) << n << " " << a;
  }
  EXPECT_EQ(lock.state(), FringeLockState::kLocked);
  EXPECT_FALSE(lock.saturated());
}

TEST(FringeLock, ARampIsFollowedWithTheLagRateOverGainAndFrameRate) {
  FringeLock lock(FringeLockParams{});  // g = 0.5
  lock.start({10.0, 0.0, 0.0});
  const double f_Hz = 30.0, v_nm_per_s = 0.6;
  Cavity cav;
  double error_nm = 0.0;
  for (int k = 0; k < 200; ++k) {
    cav.drift[0] = v_nm_per_s * k / f_Hz;
    const FringeAxes m = cav.measure(lock.correction());
    error_nm = m[0] - 10.0;
    lock.update(m, true);
  }
  // e_{k+1} = (1 - g) e_k + v / f: each frame sees the path v / (g f) = 0.04 nm past the set
  // point once the start has decayed ((1 - g)^200).
  EXPECT_NEAR(error_nm, v_nm_per_s / (0.5 * f_Hz), 1e-9);
}

TEST(FringeLock, OneFrameMovesAtMostMaxStepAndTheTotalStopsAtMaxCorrection) {
  FringeLockParams p;
  p.gain_per_frame = 1.0;
  p.max_step = {100.0, 5.0, 5.0};
  p.max_correction = {250.0, 5.0, 5.0};
  FringeLock lock(p);
  lock.start({});
  const Cavity cav{{-1000.0, 0.0, 0.0}};
  lock.update(cav.measure(lock.correction()), true);
  EXPECT_DOUBLE_EQ(lock.correction()[0], 100.0);
  EXPECT_FALSE(lock.saturated());
  lock.update(cav.measure(lock.correction()), true);
  lock.update(cav.measure(lock.correction()), true);
  EXPECT_DOUBLE_EQ(lock.correction()[0], 250.0);
  EXPECT_TRUE(lock.saturated());  // 1000 nm of drift is beyond what it was allowed to hold
}

TEST(FringeLock, LostFringesHoldTheCorrectionThenLoseTheLockAndAFrameLocksAgain) {
  FringeLock lock(FringeLockParams{});
  lock.start({});
  const Cavity cav{{30.0, 1.0, -1.0}};
  for (int k = 0; k < 20; ++k)
    lock.update(cav.measure(lock.correction()), true);
  const FringeAxes held = lock.correction();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (std::uint32_t k = 1; k <= 5; ++k) {
    // No frame, or one whose fit gave no number: the same.
    lock.update(k == 2 ? FringeAxes{nan, 0.0, 0.0} : FringeAxes{1e9, 1e9, 1e9}, k == 2);
    EXPECT_EQ(lock.correction(), held) << k;  // no jump
    EXPECT_EQ(lock.lost_frames(), k);
    EXPECT_EQ(lock.state(), k < 5 ? FringeLockState::kHolding : FringeLockState::kLost) << k;
  }
  EXPECT_EQ(std::string_view(to_string(lock.state())), "lost: semi-closed loop alone");
  // The cavity moved 4 nm while the fringes were gone; the next frame corrects half of it.
  const Cavity moved{{34.0, 1.0, -1.0}};
  const double before = moved.measure(lock.correction())[0];
  lock.update(moved.measure(lock.correction()), true);
  EXPECT_EQ(lock.state(), FringeLockState::kLocked);
  EXPECT_EQ(lock.lost_frames(), 0U);
  EXPECT_NEAR(moved.measure(lock.correction())[0], before / 2.0, 1e-9);
}

TEST(FringeLock, AStepOfTheSetPointMovesThePathByTheStep) {
  FringeLock lock(FringeLockParams{});
  lock.start({});
  const Cavity cav{{5.0, 0.0, 0.0}};
  for (int k = 0; k < 40; ++k)
    lock.update(cav.measure(lock.correction()), true);
  lock.set_point({79.1, 0.0, 0.0});  // lambda / 8 of mirror motion
  for (int k = 0; k < 40; ++k)
    lock.update(cav.measure(lock.correction()), true);
  EXPECT_NEAR(cav.measure(lock.correction())[0], 79.1, 1e-9);
}

TEST(FringeLock, NotStartedItCorrectsNothing) {
  FringeLock lock(FringeLockParams{});
  lock.update({100.0, 1.0, 1.0}, true);
  EXPECT_EQ(lock.correction(), (FringeAxes{0.0, 0.0, 0.0}));
  EXPECT_EQ(lock.state(), FringeLockState::kOff);
}

TEST(FringeLock, ParametersOutsideTheirRangesAreRefusedNamingTheKey) {
  EXPECT_EQ(std::string_view(fringe_lock_problem(FringeLockParams{})), "");
  const auto problem = [](auto change) {
    FringeLockParams p;
    change(p);
    return std::string_view(fringe_lock_problem(p));
  };
  EXPECT_NE(problem([](auto& p) { p.gain_per_frame = 1.2; }).find("gain_per_frame"),
            std::string_view::npos);
  EXPECT_NE(problem([](auto& p) { p.gain_per_frame = 0.0; }).find("gain_per_frame"),
            std::string_view::npos);
  EXPECT_NE(problem([](auto& p) { p.max_step[1] = -1.0; }).find("max_step"),
            std::string_view::npos);
  EXPECT_NE(problem([](auto& p) { p.max_correction[0] = 10.0; }).find("max_correction"),
            std::string_view::npos);
  EXPECT_NE(problem([](auto& p) { p.max_correction[2] = std::nan(""); }).find("max_correction"),
            std::string_view::npos);
  EXPECT_NE(problem([](auto& p) { p.max_lost_frames = 0; }).find("max_lost_frames"),
            std::string_view::npos);
}

// One frame of delay: at g = 1 the offset is gone after one frame (deadbeat); the range's edge.
TEST(FringeLock, AtGainOneAnOffsetIsGoneInOneFrame) {
  FringeLockParams p;
  p.gain_per_frame = 1.0;
  FringeLock lock(p);
  lock.start({});
  const Cavity cav{{50.0, 2.0, -2.0}};
  lock.update(cav.measure(lock.correction()), true);
  for (double e : cav.measure(lock.correction()))
    EXPECT_NEAR(e, 0.0, 1e-12);
}

}  // namespace
}  // namespace piezoshift::control
