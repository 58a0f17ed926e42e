#pragma once
// Motion transmission matrix, the second Eq. 8 of the paper:
//   S = A Z_S
// maps the linearized desired displacements of the three measurement points P1..P3 (um) to the
// three actuator targets as their strain-gauge sensors read them (um).
//
// Real-time safe: no heap, no exceptions, no I/O.
#include "piezoshift/control/vec3.hpp"

namespace piezoshift::control {

template <class T>
struct BasicTransmissionMatrix {
  //! Paper, Section 4: A identified by least squares with the laser interferometer.
  BasicMat3<T> a = convert<T>(
      Mat3{{{-0.4218, 0.6030, 0.6547}, {0.3482, -0.1491, 0.6962}, {0.6321, 0.4397, -0.2980}}});

  static constexpr BasicTransmissionMatrix identity() noexcept {
    return BasicTransmissionMatrix{
        BasicMat3<T>{{{T(1), T(0), T(0)}, {T(0), T(1), T(0)}, {T(0), T(0), T(1)}}}};
  }

  //! S = A Z_S
  constexpr BasicVec3<T> operator()(const BasicVec3<T>& z_s_um) const noexcept {
    return multiply(a, z_s_um);
  }
};

using TransmissionMatrix = BasicTransmissionMatrix<double>;

template <class To, class From>
constexpr BasicTransmissionMatrix<To> convert(const BasicTransmissionMatrix<From>& m) noexcept {
  return BasicTransmissionMatrix<To>{convert<To>(m.a)};
}

}  // namespace piezoshift::control
