#pragma once
// The stacked piezo actuator (paper, Section 2.1, Table 1) as the twin sees it: its stack voltage
// v (the amplifier's output) gives a free elongation, the elongation it would have with no load,
//   x_free = x_nom s_i (y(v) + C(t)) / (1 + C_step(t_ref))
// with y the Prandtl-Ishlinskii hysteresis (hysteresis.hpp, y = 1 at 150 V on the major loop),
// C the creep chain driven by y (creep.hpp), x_nom the nominal stroke (16 um, from the design's
// ActuatorParams), s_i a per-stack stroke factor (manufacturing spread), and the division making
// x_nom the free elongation 0.1 s after a 0 -> 150 V step (t_ref = 0.1 s, the reference time of
// PI's creep law). The stack is a spring k_a (Table 1: 70 N/um) in series with that source; its
// moving mass is folded into the leg (mechanics.hpp) as m_a = k_a / (2 pi f_a)^2 (Table 1:
// f_a = 30 kHz gives 1.97 g), the mass that gives a fixed-free stack its first mode.
#include <array>

#include "piezoshift/plant/creep.hpp"
#include "piezoshift/plant/hysteresis.hpp"

namespace piezoshift::plant {

struct PiezoParams {
  HysteresisParams hysteresis{};
  CreepParams creep{};
  //! t_ref: the nominal stroke is the free elongation this long after a 0 -> 150 V step
  //! (PI tutorial: creep is referred to the displacement 0.1 s after the voltage change)
  double creep_reference_time_s = 0.1;
  //! s_i: each stack's free stroke over the nominal one (stacks are sold with a stroke
  //! tolerance). Identified from Section 4.1 (docs/twin.md, "Per-leg stroke"): the semi-closed
  //! travel of 11.5 um is the weakest leg's, while the open-loop 12.9 um fixes the mean; the
  //! spread keeps both the plate's Z at O and the mean of P1..P3 at the nominal stack's value.
  std::array<double, 3> free_stroke_scale{1.011, 0.875, 1.114};

  bool operator==(const PiezoParams&) const = default;
};

}  // namespace piezoshift::plant
