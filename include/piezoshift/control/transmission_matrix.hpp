#pragma once
// Motion transmission matrix, the second Eq. 8 of the paper:
//   S = A Z_S
// maps the linearized desired displacements of the three measurement points P1..P3 (um) to the
// three actuator targets as their strain-gauge sensors read them (um).
//
// Real-time safe: no heap, no exceptions, no I/O.
#include "piezoshift/control/vec3.hpp"

namespace piezoshift::control {

struct TransmissionMatrix {
  //! Paper, Section 4: A identified by least squares with the laser interferometer.
  Mat3 a{{{-0.4218, 0.6030, 0.6547}, {0.3482, -0.1491, 0.6962}, {0.6321, 0.4397, -0.2980}}};

  static constexpr TransmissionMatrix identity() noexcept {
    return TransmissionMatrix{Mat3{{{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}}}};
  }

  //! S = A Z_S
  constexpr Vec3 operator()(const Vec3& z_s_um) const noexcept { return multiply(a, z_s_um); }
};

}  // namespace piezoshift::control
