#pragma once
// Fixed-size three-channel values for the controller core: one entry per actuator or per
// measurement point. Plain std::array so the real-time path never touches the heap.
//
// Scalar type: every type of the core is a template on its scalar T (BasicVec3<T>,
// BasicIncrementalPid<T>, ...) with the host's double as the plain name (Vec3, IncrementalPid,
// ...); the firmware (firmware/, docs/mcu.md) instantiates float for a single-precision FPU.
// Constants in the algorithms are written T(...) so float code never promotes to double.
#include <array>
#include <cstddef>
#include <type_traits>

namespace piezoshift::control {

inline constexpr std::size_t kChannels = 3;

template <class T>
using BasicVec3 = std::array<T, kChannels>;
template <class T>
using BasicMat3 = std::array<BasicVec3<T>, kChannels>;  // row-major: m[row][col]

using Vec3 = BasicVec3<double>;
using Mat3 = BasicMat3<double>;

//! y = M x
template <class T>
constexpr BasicVec3<T> multiply(const BasicMat3<T>& m, const BasicVec3<T>& x) noexcept {
  BasicVec3<T> y{};
  for (std::size_t r = 0; r < kChannels; ++r) {
    y[r] = m[r][0] * x[0] + m[r][1] * x[1] + m[r][2] * x[2];
  }
  return y;
}

template <class T = double>
constexpr BasicVec3<T> filled(std::type_identity_t<T> v) noexcept {
  return BasicVec3<T>{v, v, v};
}

//! The same values in another scalar type (double parameters to the firmware's float).
template <class To, class From>
constexpr BasicVec3<To> convert(const BasicVec3<From>& v) noexcept {
  return BasicVec3<To>{static_cast<To>(v[0]), static_cast<To>(v[1]), static_cast<To>(v[2])};
}
template <class To, class From>
constexpr BasicMat3<To> convert(const BasicMat3<From>& m) noexcept {
  return BasicMat3<To>{convert<To>(m[0]), convert<To>(m[1]), convert<To>(m[2])};
}

}  // namespace piezoshift::control
