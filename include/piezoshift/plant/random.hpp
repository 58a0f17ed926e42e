#pragma once
// The twin's one source of randomness: a std::mt19937_64 seeded once, with every deviate made
// here from its raw 64-bit output so that the same seed gives the same numbers with any standard
// library (std::normal_distribution and std::uniform_real_distribution are not specified
// bit-for-bit by the standard; mt19937_64 is).
//
//   uniform()  = ((bits >> 11) + 0.5) 2^-53                      in (0, 1), 53 random bits
//   normal()   the ziggurat method with 128 layers (Marsaglia and Tsang 2000, in Doornik's 2005
//              form "ZIGNOR", which draws the layer and the abscissa from independent bits):
//                bits = one 64-bit draw;  i = bits & 127;  u = 2 ((bits >> 11) + 0.5) 2^-53 - 1
//                |u| < x_{i+1} / x_i    -> u x_i                          (~98.8 % of draws)
//                i = 0                  -> the tail beyond r = 3.442619855899 (Marsaglia's method)
//                otherwise the wedge    -> x = u x_i if f(x_{i+1}) + U (f(x_i) - f(x_{i+1})) <
//                                          f(x), else draw again;  f(x) = exp(-x^2 / 2)
//              Layers: x_0 = v / f(r), x_1 = r, x_i = sqrt(-2 ln(v / x_{i-1} + f(x_{i-1}))),
//              x_128 = 0, v = 9.91256303526217e-3 (the common area of the 128 layers).
// The tables are built once per Rng with std::exp and std::log.
//
// Real-time safe (uniform, normal): no heap, no exceptions, no I/O.
#include <array>
#include <cmath>
#include <cstdint>
#include <random>

namespace piezoshift::plant {

class Rng {
 public:
  explicit Rng(std::uint64_t seed) : engine_(seed) {
    constexpr double r = kZigR, v = kZigV;
    double f = std::exp(-0.5 * r * r);
    x_[0] = v / f;
    x_[1] = r;
    x_[kLayers] = 0.0;
    for (std::size_t i = 2; i < kLayers; ++i) {
      x_[i] = std::sqrt(-2.0 * std::log(v / x_[i - 1] + f));
      f = std::exp(-0.5 * x_[i] * x_[i]);
    }
    for (std::size_t i = 0; i < kLayers; ++i)
      ratio_[i] = x_[i + 1] / x_[i];
  }

  //! Uniform in the open interval (0, 1).
  double uniform() noexcept { return to_unit(engine_()); }

  //! Standard normal deviate (mean 0, variance 1).
  double normal() noexcept {
    for (;;) {
      const std::uint64_t bits = engine_();
      const std::size_t i = static_cast<std::size_t>(bits & (kLayers - 1));
      const double u = 2.0 * to_unit(bits) - 1.0;
      if (std::fabs(u) < ratio_[i])
        return u * x_[i];
      if (i == 0)
        return tail(u < 0.0);
      const double x = u * x_[i];
      const double f0 = std::exp(-0.5 * (x_[i] * x_[i] - x * x));
      const double f1 = std::exp(-0.5 * (x_[i + 1] * x_[i + 1] - x * x));
      if (f1 + uniform() * (f0 - f1) < 1.0)
        return x;
    }
  }

 private:
  static constexpr std::size_t kLayers = 128;
  static constexpr double kZigR = 3.442619855899;
  static constexpr double kZigV = 9.91256303526217e-3;

  static double to_unit(std::uint64_t bits) noexcept {
    return (static_cast<double>(bits >> 11) + 0.5) * 0x1.0p-53;
  }

  // Marsaglia's tail method beyond r.
  double tail(bool negative) noexcept {
    double x = 0.0, y = 0.0;
    do {
      x = std::log(uniform()) / kZigR;
      y = std::log(uniform());
    } while (-2.0 * y < x * x);
    return negative ? x - kZigR : kZigR - x;
  }

  std::mt19937_64 engine_;
  std::array<double, kLayers + 1> x_{};
  std::array<double, kLayers> ratio_{};
};

}  // namespace piezoshift::plant
