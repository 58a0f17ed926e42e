#include "piezoshift/psi/phase_algorithms.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <fmt/core.h>
#include <Eigen/Dense>

#include "piezoshift/core/input_error.hpp"

#include "phase_fits.hpp"

namespace piezoshift::psi {
namespace {

using detail::kPi;
using detail::uniform_steps;
using detail::wrap;
using cd = std::complex<double>;

// Builds c_k = d_k + i n_k and refers it to frame 0 through arg H(+1).
WeightedSum from_real(std::span<const double> n, std::span<const double> d,
                      std::vector<double> steps) {
  WeightedSum w;
  for (std::size_t k = 0; k < n.size(); ++k)
    w.c.emplace_back(d[k], n[k]);
  w.steps_rad = std::move(steps);
  w.reference_rad = std::arg(characteristic(w, w.steps_rad, 1.0));
  return w;
}

// The 13-frame pi/4 algorithm: Hann window times exp(-i delta), projected onto the coefficient
// vectors with sum c = 0, sum c exp(-i delta) = 0 and sum c delta exp(-i delta) = 0.
WeightedSum frame13() {
  constexpr int kN = 13;
  const std::vector<double> delta = uniform_steps(kN, kPi / 4.0);
  Eigen::VectorXcd c0(kN);
  Eigen::MatrixXcd C(3, kN);
  for (int k = 0; k < kN; ++k) {
    const double s = std::sin(kPi * (k + 1) / (kN + 1));
    const cd e = std::polar(1.0, -delta[static_cast<std::size_t>(k)]);
    c0(k) = s * s * e;
    C(0, k) = 1.0;
    C(1, k) = e;
    C(2, k) = delta[static_cast<std::size_t>(k)] * e;
  }
  const Eigen::MatrixXcd CCh = C * C.adjoint();
  const Eigen::VectorXcd c = c0 - C.adjoint() * CCh.ldlt().solve(C * c0);
  WeightedSum w;
  for (int k = 0; k < kN; ++k)
    w.c.push_back(c(k));
  w.steps_rad = delta;
  w.reference_rad = std::arg(characteristic(w, w.steps_rad, 1.0));
  return w;
}

void check_frames(std::span<const Map> frames, const Mask& mask, Algorithm a) {
  const int need = required_frames(a);
  const int have = static_cast<int>(frames.size());
  if (need > 0 && have != need)
    throw std::invalid_argument(
        fmt::format("{} needs {} frames, got {}", algorithm_name(a), need, have));
  if (have < 3)
    throw std::invalid_argument(
        fmt::format("{} needs at least 3 frames, got {}", algorithm_name(a), have));
  for (const Map& f : frames)
    if (f.width != mask.width || f.height != mask.height)
      throw std::invalid_argument("frames and mask differ in size");
}

PhaseResult empty_result(const Mask& mask) {
  PhaseResult r;
  r.phase_rad = Map(mask.width, mask.height, std::nan(""));
  r.modulation = Map(mask.width, mask.height, std::nan(""));
  return r;
}

// The masked pixel indices, so the loops below touch only pupil pixels.
std::vector<std::size_t> pupil_pixels(const Mask& mask) {
  std::vector<std::size_t> idx;
  idx.reserve(mask.size());
  for (std::size_t p = 0; p < mask.size(); ++p)
    if (mask.v[p])
      idx.push_back(p);
  return idx;
}

void apply_weighted_sum(std::span<const Map> frames, const std::vector<std::size_t>& pix,
                        const WeightedSum& w, double min_modulation, PhaseResult& r) {
  const std::size_t nf = frames.size();
  std::vector<double> re(nf), im(nf);
  for (std::size_t k = 0; k < nf; ++k) {
    re[k] = w.c[k].real();
    im[k] = w.c[k].imag();
  }
  const double gain = 2.0 / std::abs(characteristic(w, w.steps_rad, 1.0));
  for (const std::size_t p : pix) {
    double sr = 0.0, si = 0.0;
    for (std::size_t k = 0; k < nf; ++k) {
      const double v = frames[k].v[p];
      sr += re[k] * v;
      si += im[k] * v;
    }
    const double b = gain * std::hypot(sr, si);
    r.modulation.v[p] = b;
    r.phase_rad.v[p] =
        b > min_modulation ? wrap(std::atan2(si, sr) - w.reference_rad) : std::nan("");
  }
}

void carre(std::span<const Map> frames, const std::vector<std::size_t>& pix, double min_modulation,
           PhaseResult& r) {
  std::vector<double> half_steps;
  half_steps.reserve(pix.size());
  for (const std::size_t p : pix) {
    const double i0 = frames[0].v[p], i1 = frames[1].v[p], i2 = frames[2].v[p], i3 = frames[3].v[p];
    const double P = 3.0 * (i1 - i2) - (i0 - i3);
    const double Q = (i0 - i3) + (i1 - i2);
    const double num = std::copysign(std::sqrt(std::fabs(P * Q)), i1 - i2);
    const double den = (i1 + i2) - (i0 + i3);
    r.phase_rad.v[p] = std::atan2(num, den);
    // |S| = 8 B sin^2 a cos a: with a near pi/4 that is 2 sqrt(2) B
    r.modulation.v[p] = std::hypot(num, den) / (2.0 * std::numbers::sqrt2);
    if (Q != 0.0 && P / Q > 0.0 && r.modulation.v[p] > min_modulation)
      half_steps.push_back(std::atan(std::sqrt(P / Q)));
  }
  double a = kPi / 4.0;
  if (!half_steps.empty()) {
    const auto mid = half_steps.begin() + static_cast<std::ptrdiff_t>(half_steps.size() / 2);
    std::nth_element(half_steps.begin(), mid, half_steps.end());
    a = *mid;
  }
  for (const std::size_t p : pix)
    r.phase_rad.v[p] =
        r.modulation.v[p] > min_modulation ? wrap(r.phase_rad.v[p] - 3.0 * a) : std::nan("");
  r.steps_rad = uniform_steps(4, 2.0 * a);
}

}  // namespace

std::string_view algorithm_name(Algorithm a) {
  switch (a) {
    case Algorithm::kFourStep:
      return "4step";
    case Algorithm::kCarre:
      return "carre";
    case Algorithm::kHariharan5:
      return "hariharan5";
    case Algorithm::kDeGroot7:
      return "degroot7";
    case Algorithm::kFrame13:
      return "frame13";
    case Algorithm::kLeastSquares:
      return "lsq";
    case Algorithm::kAia:
      return "aia";
    case Algorithm::kTiltAia:
      return "tilt-aia";
  }
  return "?";
}

std::vector<Algorithm> all_algorithms() {
  return {Algorithm::kFourStep, Algorithm::kCarre,   Algorithm::kHariharan5,
          Algorithm::kDeGroot7, Algorithm::kFrame13, Algorithm::kLeastSquares,
          Algorithm::kAia,      Algorithm::kTiltAia};
}

Algorithm parse_algorithm(std::string_view name) {
  std::string names;
  for (const Algorithm a : all_algorithms()) {
    if (algorithm_name(a) == name)
      return a;
    names += (names.empty() ? "" : ", ") + std::string(algorithm_name(a));
  }
  throw core::InputError(fmt::format("--algorithm {}: unknown (one of {})", name, names));
}

int required_frames(Algorithm a) {
  switch (a) {
    case Algorithm::kFourStep:
    case Algorithm::kCarre:
      return 4;
    case Algorithm::kHariharan5:
      return 5;
    case Algorithm::kDeGroot7:
      return 7;
    case Algorithm::kFrame13:
      return 13;
    default:
      return 0;
  }
}

double nominal_step_rad(Algorithm a) {
  return a == Algorithm::kFrame13 ? kPi / 4.0 : kPi / 2.0;
}

WeightedSum weighted_sum(Algorithm a) {
  switch (a) {
    case Algorithm::kFourStep: {
      const std::array<double, 4> n{0, -1, 0, 1}, d{1, 0, -1, 0};
      return from_real(n, d, uniform_steps(4, kPi / 2.0));
    }
    case Algorithm::kHariharan5: {
      const std::array<double, 5> n{0, -2, 0, 2, 0}, d{1, 0, -2, 0, 1};
      return from_real(n, d, uniform_steps(5, kPi / 2.0));
    }
    case Algorithm::kDeGroot7: {
      // the literature's (-I1 + 7 I3 - 7 I5 + I7) / (-4 I2 + 8 I4 - 4 I6), 1-based
      const std::array<double, 7> n{-1, 0, 7, 0, -7, 0, 1}, d{0, -4, 0, 8, 0, -4, 0};
      return from_real(n, d, uniform_steps(7, kPi / 2.0));
    }
    case Algorithm::kFrame13:
      return frame13();
    default:
      throw std::invalid_argument(fmt::format("{} is not a fixed weighted sum", algorithm_name(a)));
  }
}

WeightedSum least_squares_sum(std::span<const double> steps_rad) {
  const auto n = static_cast<Eigen::Index>(steps_rad.size());
  if (n < 3)
    throw std::invalid_argument("least squares needs at least 3 steps");
  Eigen::MatrixXd R(n, 3);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double d = steps_rad[static_cast<std::size_t>(k)];
    R.row(k) << 1.0, std::cos(d), -std::sin(d);
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(R);
  const Eigen::VectorXd sv = svd.singularValues();
  if (sv(2) < 1e-6 * sv(0))
    throw std::invalid_argument("least squares: the steps do not separate the phase");
  const Eigen::MatrixXd P = (R.transpose() * R).ldlt().solve(R.transpose());
  std::vector<double> nn(static_cast<std::size_t>(n)), dd(static_cast<std::size_t>(n));
  for (Eigen::Index k = 0; k < n; ++k) {
    dd[static_cast<std::size_t>(k)] = P(1, k);
    nn[static_cast<std::size_t>(k)] = P(2, k);
  }
  WeightedSum w = from_real(nn, dd, std::vector<double>(steps_rad.begin(), steps_rad.end()));
  w.reference_rad = 0.0;  // exact by construction: atan2(B sin phi, B cos phi)
  return w;
}

std::complex<double> characteristic(const WeightedSum& w, std::span<const double> steps_rad,
                                    double s) {
  cd h = 0.0;
  for (std::size_t k = 0; k < w.c.size() && k < steps_rad.size(); ++k)
    h += w.c[k] * std::polar(1.0, s * steps_rad[k]);
  return h;
}

double phase_error_pv_rad(const WeightedSum& w, std::span<const double> steps_rad) {
  const double r =
      std::abs(characteristic(w, steps_rad, -1.0)) / std::abs(characteristic(w, steps_rad, 1.0));
  return 2.0 * std::asin(std::min(r, 1.0));
}

PhaseResult wrapped_phase(std::span<const Map> frames, const Mask& mask, const PhaseOptions& o) {
  check_frames(frames, mask, o.algorithm);
  PhaseResult r = empty_result(mask);
  const std::vector<std::size_t> pix = pupil_pixels(mask);
  const std::size_t nf = frames.size();
  switch (o.algorithm) {
    case Algorithm::kCarre:
      carre(frames, pix, o.min_modulation, r);
      return r;
    case Algorithm::kLeastSquares: {
      const std::vector<double> steps =
          o.steps_rad.empty() ? uniform_steps(static_cast<int>(nf), kPi / 2.0) : o.steps_rad;
      if (steps.size() != nf)
        throw std::invalid_argument(fmt::format("lsq: {} steps for {} frames", steps.size(), nf));
      const WeightedSum w = least_squares_sum(steps);
      apply_weighted_sum(frames, pix, w, o.min_modulation, r);
      r.steps_rad = steps;
      return r;
    }
    case Algorithm::kAia:
    case Algorithm::kTiltAia:
      detail::fit_phase(frames, mask, pix, o, r);
      return r;
    default: {
      const WeightedSum w = weighted_sum(o.algorithm);
      apply_weighted_sum(frames, pix, w, o.min_modulation, r);
      r.steps_rad = w.steps_rad;
      return r;
    }
  }
}

FrameShiftColumns shift_columns(const std::vector<FrameShift>& shifts) {
  FrameShiftColumns c;
  for (const FrameShift& s : shifts) {
    c.piston_rad.push_back(s.piston_rad);
    c.tip_rad.push_back(s.tip_rad);
    c.tilt_rad.push_back(s.tilt_rad);
  }
  return c;
}

}  // namespace piezoshift::psi
