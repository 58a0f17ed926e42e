#pragma once
// Portable fixed-seed Gaussian noise for tests: std::mt19937_64 is fully specified by the
// standard, std::normal_distribution is not (it differs between standard libraries), so the
// normal deviates are made here by Box-Muller from the engine's raw 64-bit output.
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>

namespace piezoshift::test {

class GaussianNoise {
 public:
  GaussianNoise(std::uint64_t seed, double sigma) : engine_(seed), sigma_(sigma) {}
  double operator()() {
    const double u1 = uniform_open();
    const double u2 = uniform_open();
    return sigma_ * std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  }

 private:
  double uniform_open() {  // in (0, 1)
    return (static_cast<double>(engine_() >> 11) + 0.5) * 0x1.0p-53;
  }
  std::mt19937_64 engine_;
  double sigma_;
};

}  // namespace piezoshift::test
