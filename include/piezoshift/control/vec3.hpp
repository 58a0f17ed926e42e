#pragma once
// Fixed-size three-channel values for the controller core: one entry per actuator or per
// measurement point. Plain std::array so the real-time path never touches the heap.
#include <array>
#include <cstddef>

namespace piezoshift::control {

inline constexpr std::size_t kChannels = 3;

using Vec3 = std::array<double, kChannels>;
using Mat3 = std::array<Vec3, kChannels>;  // row-major: m[row][col]

//! y = M x
constexpr Vec3 multiply(const Mat3& m, const Vec3& x) noexcept {
  Vec3 y{};
  for (std::size_t r = 0; r < kChannels; ++r) {
    y[r] = m[r][0] * x[0] + m[r][1] * x[1] + m[r][2] * x[2];
  }
  return y;
}

constexpr Vec3 filled(double v) noexcept {
  return Vec3{v, v, v};
}

}  // namespace piezoshift::control
