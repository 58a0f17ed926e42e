// Built with -fno-exceptions -fno-rtti: proves the controller core needs neither, and that a full
// controller tick is usable in a constant expression (so it cannot allocate).
#include "piezoshift/control/fringe_lock.hpp"
#include "piezoshift/control/parameter_check.hpp"
#include "piezoshift/control/semi_closed_loop.hpp"

namespace {

using piezoshift::control::SemiClosedLoopController;
using piezoshift::control::Vec3;

constexpr double first_tick_dac_V() {
  SemiClosedLoopController c;
  const auto out = c.update(Vec3{5.0, 5.0, 5.0}, Vec3{0.0, 0.0, 0.0});
  return out.dac_V[0];
}

// First tick from rest: u = (kp + ki + kd) e = 0.801 e, e = S_1 = (A p(5) 1)_1, then x 0.625 V/um.
constexpr double kP5 = ((-0.0001009 * 5.0 + 0.000389) * 5.0 + 1.014) * 5.0 + 0.2914;
constexpr double kExpected = 0.801 * kP5 * (-0.4218 + 0.6030 + 0.6547) * 0.625;
static_assert(first_tick_dac_V() - kExpected < 1e-12 && kExpected - first_tick_dac_V() < 1e-12);
static_assert(noexcept(SemiClosedLoopController{}.update(Vec3{}, Vec3{})));

// The float instantiation the firmware runs (firmware/, docs/mcu.md): the same tick, in float.
constexpr float first_tick_dac_V_float() {
  using piezoshift::control::BasicSemiClosedLoopController;
  using piezoshift::control::SemiClosedLoopParams;
  BasicSemiClosedLoopController<float> c(
      piezoshift::control::convert<float>(SemiClosedLoopParams{}));
  const auto out = c.update({5.0F, 5.0F, 5.0F}, {0.0F, 0.0F, 0.0F});
  return out.dac_V[0];
}
static_assert(first_tick_dac_V_float() - kExpected < 1e-6 &&
              kExpected - first_tick_dac_V_float() < 1e-6);

// The check the loop runs before it takes a parameter set is part of the core too.
static_assert(piezoshift::control::params_problem(piezoshift::control::SemiClosedLoopParams{},
                                                  1e-3) ==
              piezoshift::control::ParamsProblem::kNone);
static_assert(noexcept(
    piezoshift::control::params_problem(piezoshift::control::SemiClosedLoopParams{}, 1e-3)));

// The fringe lock's frame, in a constant expression: g = 0.5 takes half of a 10 nm offset.
constexpr double fringe_lock_first_correction_nm() {
  piezoshift::control::FringeLock lock(piezoshift::control::FringeLockParams{});
  lock.start({0.0, 0.0, 0.0});
  return lock.update({10.0, 0.0, 0.0}, true)[0];
}
static_assert(fringe_lock_first_correction_nm() == -5.0);
static_assert(
    piezoshift::control::fringe_lock_problem(piezoshift::control::FringeLockParams{})[0] == '\0');

}  // namespace

int main() {
  SemiClosedLoopController c;
  Vec3 sgs{0.0, 0.0, 0.0};
  double last = 0.0;
  for (int k = 0; k < 5; ++k)
    last = c.update(Vec3{5.0, 5.0, 5.0}, sgs).dac_V[1];
  return (last > 0.0 && last <= 10.0) ? 0 : 1;
}
