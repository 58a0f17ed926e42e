#pragma once
// Open-loop plant tests: one control period of the twin with the DAQ volts held, in the twin's
// own order (plant/twin.hpp): write_ao, advance, read_ai. A closed loop goes through the loop
// every command ships (runtime/control_loop.hpp, rig/bench.hpp), never through this.
#include "piezoshift/control/vec3.hpp"
#include "piezoshift/plant/twin.hpp"

namespace piezoshift::testing {

inline const control::Vec3& hold_one_period(plant::Twin& twin, const control::Vec3& ao_V) {
  twin.write_ao(ao_V);
  twin.advance();
  return twin.read_ai();
}

}  // namespace piezoshift::testing
