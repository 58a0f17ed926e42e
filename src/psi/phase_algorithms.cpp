#include "piezoshift/psi/phase_algorithms.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include <fmt/core.h>
#include <Eigen/Dense>

#include "piezoshift/core/input_error.hpp"

namespace piezoshift::psi {
namespace {

constexpr double kPi = std::numbers::pi;
using cd = std::complex<double>;

double wrap(double a) {
  return std::remainder(a, 2.0 * kPi);
}

std::vector<double> uniform_steps(int n, double step) {
  std::vector<double> d(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k)
    d[static_cast<std::size_t>(k)] = k * step;
  return d;
}

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

// AIA step (1): per pixel (A, B cos phi, B sin phi) with the steps known.
void aia_pixels(std::span<const Map> frames, const std::vector<std::size_t>& pix,
                const std::vector<double>& steps, std::vector<double>& phi,
                std::vector<double>& b) {
  const std::size_t nf = frames.size();
  Eigen::MatrixXd R(static_cast<Eigen::Index>(nf), 3);
  for (std::size_t k = 0; k < nf; ++k)
    R.row(static_cast<Eigen::Index>(k)) << 1.0, std::cos(steps[k]), -std::sin(steps[k]);
  const Eigen::MatrixXd P = (R.transpose() * R).ldlt().solve(R.transpose());  // 3 x nf
  for (std::size_t q = 0; q < pix.size(); ++q) {
    double u1 = 0.0, u2 = 0.0;
    for (std::size_t k = 0; k < nf; ++k) {
      const double v = frames[k].v[pix[q]];
      u1 += P(1, static_cast<Eigen::Index>(k)) * v;
      u2 += P(2, static_cast<Eigen::Index>(k)) * v;
    }
    phi[q] = std::atan2(u2, u1);
    b[q] = std::hypot(u1, u2);
  }
}

// AIA step (2): per frame (a_k, b_k cos d_k, b_k sin d_k) with the phase known.
std::vector<double> aia_frames(std::span<const Map> frames, const std::vector<std::size_t>& pix,
                               const std::vector<double>& phi) {
  const std::size_t nf = frames.size();
  Eigen::Matrix3d Q = Eigen::Matrix3d::Zero();
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(3, static_cast<Eigen::Index>(nf));
  for (std::size_t q = 0; q < pix.size(); ++q) {
    const Eigen::Vector3d row(1.0, std::cos(phi[q]), -std::sin(phi[q]));
    Q += row * row.transpose();
    for (std::size_t k = 0; k < nf; ++k)
      rhs.col(static_cast<Eigen::Index>(k)) += row * frames[k].v[pix[q]];
  }
  const Eigen::MatrixXd v = Q.ldlt().solve(rhs);
  std::vector<double> d(nf);
  for (std::size_t k = 0; k < nf; ++k)
    d[k] = std::atan2(v(2, static_cast<Eigen::Index>(k)), v(1, static_cast<Eigen::Index>(k)));
  return d;
}

// Refers steps to frame 0 and to a positive mean step; returns the sign applied to phi.
double normalise_steps(std::vector<double>& d) {
  const double d0 = d[0];
  double sum = 0.0;  // of the wrapped increments: the direction of the sequence
  for (std::size_t k = 1; k < d.size(); ++k)
    sum += wrap(d[k] - d[k - 1]);
  for (double& x : d)
    x = wrap(x - d0);
  const double sign = sum < 0.0 ? -1.0 : 1.0;
  for (double& x : d)
    x *= sign;
  // unwrap along the sequence so that a 13-frame set reads 0, pi/4, ..., 3 pi
  for (std::size_t k = 1; k < d.size(); ++k)
    d[k] = d[k - 1] + wrap(d[k] - d[k - 1]);
  return sign;
}

void aia(std::span<const Map> frames, const std::vector<std::size_t>& pix, const PhaseOptions& o,
         PhaseResult& r, std::vector<double>& phi, std::vector<double>& b) {
  const std::size_t nf = frames.size();
  std::vector<double> steps =
      o.steps_rad.size() == nf ? o.steps_rad : uniform_steps(static_cast<int>(nf), kPi / 2.0);
  r.converged = false;
  for (r.iterations = 1; r.iterations <= o.max_iterations; ++r.iterations) {
    aia_pixels(frames, pix, steps, phi, b);
    std::vector<double> next = aia_frames(frames, pix, phi);
    // compare steps relative to frame 0 (the pair (phi, delta) is defined up to a common shift)
    double change = 0.0;
    for (std::size_t k = 0; k < nf; ++k)
      change = std::max(change, std::fabs(wrap((next[k] - next[0]) - (steps[k] - steps[0]))));
    steps = next;
    if (change < o.tolerance_rad) {
      r.converged = true;
      break;
    }
  }
  r.iterations = std::min(r.iterations, o.max_iterations);
  aia_pixels(frames, pix, steps, phi, b);
  const double d0 = steps[0];
  const double sign = normalise_steps(steps);
  for (double& x : phi)
    x = wrap(sign * (x + d0));
  r.steps_rad = steps;
}

// Tilt-aware AIA (see the header). Pixel coordinates in the pupil frame.
void tilt_aia(std::span<const Map> frames, const Mask& mask, const std::vector<std::size_t>& pix,
              const PhaseOptions& o, PhaseResult& r, std::vector<double>& phi,
              std::vector<double>& b) {
  const std::size_t nf = frames.size();
  const Pupil pupil = pupil_of(mask);
  std::vector<double> xs(pix.size()), ys(pix.size());
  for (std::size_t q = 0; q < pix.size(); ++q) {
    xs[q] = pupil.x(static_cast<int>(pix[q] % static_cast<std::size_t>(mask.width)));
    ys[q] = pupil.y(static_cast<int>(pix[q] / static_cast<std::size_t>(mask.width)));
  }
  // start from plain AIA
  PhaseResult start;
  aia(frames, pix, o, start, phi, b);
  std::vector<FrameShift> sh(nf);
  std::vector<double> a(nf, 0.0), bk(nf, 0.0);
  // plain AIA refers phi to frame 0, so frame 0 starts (and stays) at zero shift
  for (std::size_t k = 0; k < nf; ++k)
    sh[k].piston_rad = start.steps_rad[k];
  {  // background and modulation per frame from the plain result
    double sa = 0.0, sb = 0.0;
    for (std::size_t q = 0; q < pix.size(); ++q) {
      sb += b[q];
      for (std::size_t k = 0; k < nf; ++k)
        sa += frames[k].v[pix[q]];
    }
    for (std::size_t k = 0; k < nf; ++k) {
      a[k] = sa / static_cast<double>(nf * pix.size());
      bk[k] = sb / static_cast<double>(pix.size());
    }
  }
  std::vector<double> cs(nf), sn(nf);
  r.converged = false;
  int it = 1;
  for (; it <= o.max_iterations; ++it) {
    // (1) per pixel, the shifts known: 3 x 3 normal equations per pixel
    for (std::size_t q = 0; q < pix.size(); ++q) {
      Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
      Eigen::Vector3d y = Eigen::Vector3d::Zero();
      for (std::size_t k = 0; k < nf; ++k) {
        const double d = sh[k].piston_rad + sh[k].tip_rad * ys[q] + sh[k].tilt_rad * xs[q];
        const Eigen::Vector3d row(1.0, std::cos(d), -std::sin(d));
        M += row * row.transpose();
        y += row * frames[k].v[pix[q]];
      }
      const Eigen::Vector3d u = M.ldlt().solve(y);
      phi[q] = std::atan2(u(2), u(1));
      b[q] = std::hypot(u(1), u(2));
    }
    // (2) per frame, the phase known: Gauss-Newton on (a, b, piston, tip, tilt)
    double change = 0.0;
    for (std::size_t k = 0; k < nf; ++k) {
      for (int gn = 0; gn < 3; ++gn) {
        Eigen::Matrix<double, 5, 5> JtJ = Eigen::Matrix<double, 5, 5>::Zero();
        Eigen::Matrix<double, 5, 1> Jtr = Eigen::Matrix<double, 5, 1>::Zero();
        for (std::size_t q = 0; q < pix.size(); ++q) {
          const double th =
              phi[q] + sh[k].piston_rad + sh[k].tip_rad * ys[q] + sh[k].tilt_rad * xs[q];
          const double c = std::cos(th), s = std::sin(th);
          const double res = frames[k].v[pix[q]] - a[k] - bk[k] * c;
          Eigen::Matrix<double, 5, 1> J;
          J << 1.0, c, -bk[k] * s, -bk[k] * s * ys[q], -bk[k] * s * xs[q];
          JtJ.selfadjointView<Eigen::Lower>().rankUpdate(J);
          Jtr += J * res;
        }
        JtJ.triangularView<Eigen::Upper>() = JtJ.transpose();
        // frame 0's plane is pinned at zero: (phi + plane, shifts - plane) is the same data, and
        // leaving that direction free makes the alternation crawl along it
        Eigen::Matrix<double, 5, 1> dx = Eigen::Matrix<double, 5, 1>::Zero();
        if (k == 0)
          dx.head<2>() = JtJ.topLeftCorner<2, 2>().ldlt().solve(Jtr.head<2>());
        else
          dx = JtJ.ldlt().solve(Jtr);
        a[k] += dx(0);
        bk[k] += dx(1);
        sh[k].piston_rad += dx(2);
        sh[k].tip_rad += dx(3);
        sh[k].tilt_rad += dx(4);
        change = std::max({change, std::fabs(dx(2)), std::fabs(dx(3)), std::fabs(dx(4))});
      }
    }
    if (change < o.tolerance_rad) {
      r.converged = true;
      break;
    }
  }
  r.iterations = std::min(it, o.max_iterations);
  // refer to frame 0 (its plane goes into phi) and to a positive mean piston
  const FrameShift f0 = sh[0];
  double sum = 0.0;
  for (FrameShift& s : sh) {
    s.piston_rad -= f0.piston_rad;
    s.tip_rad -= f0.tip_rad;
    s.tilt_rad -= f0.tilt_rad;
    sum += s.piston_rad;
  }
  const double sign = sum < 0.0 ? -1.0 : 1.0;
  for (std::size_t q = 0; q < pix.size(); ++q)
    phi[q] = wrap(sign * (phi[q] + f0.piston_rad + f0.tip_rad * ys[q] + f0.tilt_rad * xs[q]));
  r.steps_rad.clear();
  for (FrameShift& s : sh) {
    s.piston_rad *= sign;
    s.tip_rad *= sign;
    s.tilt_rad *= sign;
    r.steps_rad.push_back(s.piston_rad);
  }
  r.shifts = sh;
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
    case Algorithm::kTiltAia: {
      std::vector<double> phi(pix.size()), b(pix.size());
      if (o.algorithm == Algorithm::kAia)
        aia(frames, pix, o, r, phi, b);
      else
        tilt_aia(frames, mask, pix, o, r, phi, b);
      for (std::size_t q = 0; q < pix.size(); ++q) {
        r.modulation.v[pix[q]] = b[q];
        r.phase_rad.v[pix[q]] = b[q] > o.min_modulation ? phi[q] : std::nan("");
      }
      return r;
    }
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
