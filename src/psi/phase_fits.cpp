#include "phase_fits.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <string>

#include <fmt/core.h>
#include <Eigen/Dense>

#include "piezoshift/psi/grid.hpp"
#include "piezoshift/psi/median.hpp"

namespace piezoshift::psi::detail {
namespace {

using cd = std::complex<double>;

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

// The steps commanded: those given, else k pi/2.
std::vector<double> commanded_steps(const PhaseOptions& o, std::size_t nf) {
  return o.steps_rad.size() == nf ? o.steps_rad : uniform_steps(static_cast<int>(nf), kPi / 2.0);
}

// PhaseResult::step_conditioning of a phase over the pupil's pixels.
double step_conditioning(const std::vector<double>& phi) {
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  for (const double p : phi) {
    const Eigen::Vector3d u(1.0, std::cos(p), std::sin(p));
    m += u * u.transpose();
  }
  if (phi.empty())
    return 0.0;
  m /= static_cast<double>(phi.size());
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(m, Eigen::EigenvaluesOnly).eigenvalues()(0);
}

void aia(std::span<const Map> frames, const std::vector<std::size_t>& pix, const PhaseOptions& o,
         PhaseResult& r, std::vector<double>& phi, std::vector<double>& b) {
  const std::size_t nf = frames.size();
  std::vector<double> steps = commanded_steps(o, nf);
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
  r.step_conditioning = step_conditioning(phi);
  const double d0 = steps[0];
  const double sign = normalise_steps(steps);
  for (double& x : phi)
    x = wrap(sign * (x + d0));
  r.steps_rad = steps;
}

// The pupil coordinates (grid.hpp) of the pupil pixels, for the shift planes.
struct PupilXY {
  std::vector<double> x, y;
};

PupilXY pupil_xy(const Mask& mask, const std::vector<std::size_t>& pix) {
  const Pupil pupil = pupil_of(mask);
  PupilXY c{std::vector<double>(pix.size()), std::vector<double>(pix.size())};
  const auto w = static_cast<std::size_t>(mask.width);
  for (std::size_t q = 0; q < pix.size(); ++q) {
    c.x[q] = pupil.x(static_cast<int>(pix[q] % w));
    c.y[q] = pupil.y(static_cast<int>(pix[q] / w));
  }
  return c;
}

double plane_at(const FrameShift& s, const PupilXY& xy, std::size_t q) {
  return s.piston_rad + s.tip_rad * xy.y[q] + s.tilt_rad * xy.x[q];
}

std::vector<FrameShift> pistons(const std::vector<double>& steps) {
  std::vector<FrameShift> sh;
  for (const double d : steps)
    sh.push_back({d, 0.0, 0.0});
  return sh;
}

// Per pixel (A, B cos phi, B sin phi) with each frame's shift plane known (3 x 3 normal equations
// per pixel): tilt-aware step (1). With res, also the frames' residual from that model,
// res[k * pixels + q].
void solve_pixels(std::span<const Map> frames, const std::vector<std::size_t>& pix,
                  const PupilXY& xy, const std::vector<FrameShift>& sh, std::vector<double>& phi,
                  std::vector<double>& b, std::vector<double>* res = nullptr) {
  const std::size_t nf = frames.size();
  std::vector<Eigen::Vector3d> rows(nf);
  for (std::size_t q = 0; q < pix.size(); ++q) {
    Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
    Eigen::Vector3d y = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < nf; ++k) {
      const double d = plane_at(sh[k], xy, q);
      rows[k] = Eigen::Vector3d(1.0, std::cos(d), -std::sin(d));
      M += rows[k] * rows[k].transpose();
      y += rows[k] * frames[k].v[pix[q]];
    }
    const Eigen::Vector3d u = M.ldlt().solve(y);
    phi[q] = std::atan2(u(2), u(1));
    b[q] = std::hypot(u(1), u(2));
    if (res)
      for (std::size_t k = 0; k < nf; ++k)
        (*res)[k * pix.size() + q] = frames[k].v[pix[q]] - rows[k].dot(u);
  }
}

// Tilt-aware step (2): per frame, the phase known, three Gauss-Newton steps on (a, b, piston, tip,
// tilt). Frame 0's plane is pinned at zero: (phi + plane, shifts - plane) is the same data, and
// left free the alternation crawls along that direction. Returns the largest plane change.
double fit_planes(std::span<const Map> frames, const std::vector<std::size_t>& pix,
                  const PupilXY& xy, const std::vector<double>& phi, std::vector<FrameShift>& sh,
                  std::vector<double>& a, std::vector<double>& bk) {
  using Vec5 = Eigen::Matrix<double, 5, 1>;
  using Mat5 = Eigen::Matrix<double, 5, 5>;
  constexpr int kGaussNewtonSteps = 1;
  constexpr double kOver = 1.6;
  double change = 0.0;
  for (std::size_t k = 0; k < frames.size(); ++k)
    for (int gn = 0; gn < kGaussNewtonSteps; ++gn) {
      Mat5 JtJ = Mat5::Zero();
      Vec5 Jtr = Vec5::Zero();
      for (std::size_t q = 0; q < pix.size(); ++q) {
        const double th = phi[q] + plane_at(sh[k], xy, q);
        const double c = std::cos(th), s = std::sin(th);
        Vec5 J;
        J << 1.0, c, -bk[k] * s, -bk[k] * s * xy.y[q], -bk[k] * s * xy.x[q];
        JtJ.selfadjointView<Eigen::Lower>().rankUpdate(J);
        Jtr += J * (frames[k].v[pix[q]] - a[k] - bk[k] * c);
      }
      JtJ.triangularView<Eigen::Upper>() = JtJ.transpose();
      Vec5 dx = Vec5::Zero();
      if (k == 0)
        dx.head<2>() = JtJ.topLeftCorner<2, 2>().ldlt().solve(Jtr.head<2>());
      else
        dx = JtJ.ldlt().solve(Jtr);
      a[k] += dx(0);
      bk[k] += dx(1);
      sh[k].piston_rad += kOver * dx(2);
      sh[k].tip_rad += kOver * dx(3);
      sh[k].tilt_rad += kOver * dx(4);
      change = std::max({change, std::fabs(dx(2)), std::fabs(dx(3)), std::fabs(dx(4))});
    }
  return change;
}

struct PlaneFit {
  std::vector<FrameShift> shifts;
  int iterations = 0;
  bool settled = false;  //!< no plane coefficient changed by more than the tolerance
  double misfit = 0.0;   //!< RMS residual of the frames from the model (frame units)
};

// The tilt-aware alternation from the given planes (frame 0's at zero).
PlaneFit alternate_planes(std::span<const Map> frames, const std::vector<std::size_t>& pix,
                          const PupilXY& xy, std::vector<FrameShift> sh, const PhaseOptions& o,
                          std::vector<double>& phi, std::vector<double>& b) {
  const std::size_t nf = frames.size();
  solve_pixels(frames, pix, xy, sh, phi, b);
  double sa = 0.0, sb = 0.0;  // background and modulation per frame start at the pupil's means
  for (std::size_t q = 0; q < pix.size(); ++q) {
    sb += b[q];
    for (std::size_t k = 0; k < nf; ++k)
      sa += frames[k].v[pix[q]];
  }
  std::vector<double> a(nf, sa / static_cast<double>(nf * pix.size()));
  std::vector<double> bk(nf, sb / static_cast<double>(pix.size()));
  PlaneFit f;
  for (f.iterations = 1; f.iterations <= o.max_iterations; ++f.iterations) {
    solve_pixels(frames, pix, xy, sh, phi, b);
    if (fit_planes(frames, pix, xy, phi, sh, a, bk) < o.tolerance_rad) {
      f.settled = true;
      break;
    }
  }
  f.iterations = std::min(f.iterations, o.max_iterations);
  std::vector<double> res(nf * pix.size());
  solve_pixels(frames, pix, xy, sh, phi, b, &res);
  double s2 = 0.0;
  for (const double e : res)
    s2 += e * e;
  f.misfit = std::sqrt(s2 / static_cast<double>(std::max<std::size_t>(res.size(), 1)));
  f.shifts = std::move(sh);
  return f;
}

// A start for the planes that needs no iteration: each frame against a phase estimate phi0, the
// best of a grid of (tip, tilt) over [-1.5, 1.5]^2 rad in steps of 0.25 rad (the basin of the
// alternation is about +-0.5 rad wide in each) with (a, b cos piston, b sin piston) solved
// linearly at each point, on at most ~4000 pupil pixels. Referred to frame 0's plane.
std::vector<FrameShift> grid_planes(std::span<const Map> frames,
                                    const std::vector<std::size_t>& pix, const PupilXY& xy,
                                    const std::vector<double>& phi0) {
  constexpr int kHalf = 6, kSide = 2 * kHalf + 1;
  constexpr double kStep = 0.25;
  const std::size_t stride = std::max<std::size_t>(1, pix.size() / 4000);
  std::vector<std::size_t> sub;
  for (std::size_t q = 0; q < pix.size(); q += stride)
    sub.push_back(q);
  // exp(i (phi0 + tip y)) and exp(i tilt x) per grid value: a product per point, no sincos
  std::vector<cd> ey(kSide * sub.size()), ex(kSide * sub.size());
  for (int g = 0; g < kSide; ++g)
    for (std::size_t m = 0; m < sub.size(); ++m) {
      const std::size_t q = sub[m];
      ey[g * sub.size() + m] = std::polar(1.0, phi0[q] + (g - kHalf) * kStep * xy.y[q]);
      ex[g * sub.size() + m] = std::polar(1.0, (g - kHalf) * kStep * xy.x[q]);
    }
  std::vector<FrameShift> sh(frames.size());
  for (std::size_t k = 0; k < frames.size(); ++k) {
    double best = std::numeric_limits<double>::infinity();
    for (int it = 0; it < kSide; ++it)
      for (int il = 0; il < kSide; ++il) {
        Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
        Eigen::Vector3d y = Eigen::Vector3d::Zero();
        double yy = 0.0;
        for (std::size_t m = 0; m < sub.size(); ++m) {
          const cd e = ey[it * sub.size() + m] * ex[il * sub.size() + m];
          const Eigen::Vector3d row(1.0, e.real(), -e.imag());
          const double v = frames[k].v[pix[sub[m]]];
          M += row * row.transpose();
          y += row * v;
          yy += v * v;
        }
        const Eigen::Vector3d u = M.ldlt().solve(y);
        if (const double cost = yy - u.dot(y); cost < best) {
          best = cost;
          sh[k] = {std::atan2(u(2), u(1)), (it - kHalf) * kStep, (il - kHalf) * kStep};
        }
      }
  }
  const FrameShift f0 = sh[0];
  for (FrameShift& s : sh)
    s = {wrap(s.piston_rad - f0.piston_rad), s.tip_rad - f0.tip_rad, s.tilt_rad - f0.tilt_rad};
  return sh;
}

// Refers the planes to frame 0's (which goes into phi) and to a positive mean step, the pistons
// unwrapped along the sequence as AIA's steps are.
void refer_planes(std::vector<FrameShift>& sh, const PupilXY& xy, std::vector<double>& phi) {
  const FrameShift f0 = sh[0];
  double sum = 0.0;  // of the wrapped increments: the direction of the sequence
  for (std::size_t k = 1; k < sh.size(); ++k)
    sum += wrap(sh[k].piston_rad - sh[k - 1].piston_rad);
  const double sign = sum < 0.0 ? -1.0 : 1.0;
  for (std::size_t q = 0; q < phi.size(); ++q)
    phi[q] = wrap(sign * (phi[q] + plane_at(f0, xy, q)));
  for (FrameShift& s : sh)
    s = {sign * wrap(s.piston_rad - f0.piston_rad), sign * (s.tip_rad - f0.tip_rad),
         sign * (s.tilt_rad - f0.tilt_rad)};
  for (std::size_t k = 1; k < sh.size(); ++k)
    sh[k].piston_rad = sh[k - 1].piston_rad + wrap(sh[k].piston_rad - sh[k - 1].piston_rad);
}

// Tilt-aware AIA (see the header) from three starts, keeping the fit that leaves the smallest
// residual: plain AIA's steps (flat planes); the grid of planes against AIA's phase; the grid
// against the least-squares phase at the commanded steps. A single start lands in a wrong basin
// once the frames' tilts reach a few tenths of a radian at the pupil edge. The starts
// run on at most ~8000 pupil pixels; the winner is then finished on all of them.
void tilt_aia(std::span<const Map> frames, const PupilXY& xy, const std::vector<std::size_t>& pix,
              const PhaseOptions& o, PhaseResult& r, std::vector<double>& phi,
              std::vector<double>& b) {
  const std::size_t stride = std::max<std::size_t>(1, pix.size() / 8000);
  std::vector<std::size_t> sub;
  PupilXY sxy;
  for (std::size_t q = 0; q < pix.size(); q += stride) {
    sub.push_back(pix[q]);
    sxy.x.push_back(xy.x[q]);
    sxy.y.push_back(xy.y[q]);
  }
  std::vector<double> sphi(sub.size()), sb(sub.size());
  PhaseResult plain;
  aia(frames, sub, o, plain, sphi, sb);
  std::vector<std::vector<FrameShift>> starts{pistons(plain.steps_rad)};
  starts.push_back(grid_planes(frames, sub, sxy, sphi));
  solve_pixels(frames, sub, sxy, pistons(commanded_steps(o, frames.size())), sphi, sb);
  starts.push_back(grid_planes(frames, sub, sxy, sphi));
  PlaneFit best;
  best.misfit = std::numeric_limits<double>::infinity();
  for (const std::vector<FrameShift>& s : starts) {
    PlaneFit f = alternate_planes(frames, sub, sxy, s, o, sphi, sb);
    // a settled fit beats one still moving; between equals, the smaller residual
    if ((f.settled && !best.settled) || (f.settled == best.settled && f.misfit < best.misfit))
      best = std::move(f);
  }
  const int start_iterations = best.iterations;
  best = alternate_planes(frames, pix, xy, best.shifts, o, phi, b);
  r.iterations = start_iterations + best.iterations;
  r.converged = best.settled;
  refer_planes(best.shifts, xy, phi);
  r.steps_rad.clear();
  for (const FrameShift& s : best.shifts)
    r.steps_rad.push_back(s.piston_rad);
  r.shifts = best.shifts;
}

// The frames' residual from the fitted model (per pixel A, B, phi; per frame its plane), as RMS
// over all frames and pixels and as its white part, from differences of horizontally adjacent
// pixels (noise is independent between pixels, a wrong model's residual is smooth). Both over
// the median modulation. Fills phi and b from the model.
void measure_residual(std::span<const Map> frames, const std::vector<std::size_t>& pix, int width,
                      const PupilXY& xy, const std::vector<FrameShift>& sh, PhaseResult& r,
                      std::vector<double>& phi, std::vector<double>& b) {
  const std::size_t nf = frames.size(), n = pix.size();
  std::vector<double> res(nf * n);
  solve_pixels(frames, pix, xy, sh, phi, b, &res);
  double s2 = 0.0, d2 = 0.0;
  std::size_t pairs = 0;
  for (const double e : res)
    s2 += e * e;
  for (std::size_t q = 0; q + 1 < n; ++q)
    if (pix[q + 1] == pix[q] + 1 && (pix[q + 1] % static_cast<std::size_t>(width)) != 0) {
      for (std::size_t k = 0; k < nf; ++k)
        d2 += std::pow(res[k * n + q + 1] - res[k * n + q], 2);
      pairs += nf;
    }
  const double bmed = median_of(b);
  const double rms = std::sqrt(s2 / static_cast<double>(std::max<std::size_t>(res.size(), 1)));
  const double white = pairs ? std::sqrt(d2 / (2.0 * static_cast<double>(pairs))) : rms;
  r.residual_rms = bmed > 0.0 ? rms / bmed : std::numeric_limits<double>::infinity();
  r.noise_rms = bmed > 0.0 ? white / bmed : std::numeric_limits<double>::infinity();
}

// Why an iterative fit is not to be trusted, "" when it is (docs/psi.md, "Fits that check
// themselves"): the phase spread too little to determine the steps (aia); it did not settle; a
// step is further than step_tolerance_rad from the commanded one; a plane is steeper than
// max_tilt_rad at the pupil edge; or the frames differ from the fitted model by more than
// max_misfit of the modulation beyond their white noise.
std::string fit_problem(Algorithm alg, const PhaseResult& r, const PhaseOptions& o,
                        std::size_t frames) {
  if (!(r.step_conditioning >= o.min_step_conditioning) && std::isfinite(r.step_conditioning))
    return fmt::format(
        "{}: the phase spans too little of a fringe over the pupil to tell the steps from it "
        "(conditioning {:.2g}, at least {:g}; 0.5 for a phase spread over a fringe or more): add "
        "tilt fringes, or use an algorithm with fixed steps",
        algorithm_name(alg), r.step_conditioning, o.min_step_conditioning);
  if (!r.converged)
    return fmt::format("{} did not converge in {} iterations", algorithm_name(alg), r.iterations);
  const std::vector<double> c = commanded_steps(o, frames);
  for (std::size_t k = 0; k < r.steps_rad.size(); ++k)
    if (const double e = wrap(r.steps_rad[k] - (c[k] - c[0])); std::fabs(e) > o.step_tolerance_rad)
      return fmt::format(
          "{}: step {} recovered at {:.3f} rad, {:+.3f} rad from the commanded {:.3f} rad (at "
          "most +-{:g} rad)",
          algorithm_name(alg), k, r.steps_rad[k], e, c[k] - c[0], o.step_tolerance_rad);
  for (std::size_t k = 0; k < r.shifts.size(); ++k)
    if (const double t = std::hypot(r.shifts[k].tip_rad, r.shifts[k].tilt_rad); t > o.max_tilt_rad)
      return fmt::format(
          "{}: frame {}'s shift plane reaches {:.3f} rad at the pupil edge (at most {:g} rad)",
          algorithm_name(alg), k, t, o.max_tilt_rad);
  const double systematic =
      std::sqrt(std::max(0.0, r.residual_rms * r.residual_rms - r.noise_rms * r.noise_rms));
  if (!(systematic <= o.max_misfit))
    return fmt::format(
        "{}: the frames differ from the fitted model by {:.4f} of the modulation RMS beyond "
        "their noise ({:.4f}); at most {:g}: a wrong solution, or frames the model does not "
        "describe",
        algorithm_name(alg), systematic, r.noise_rms, o.max_misfit);
  return {};
}

}  // namespace

void fit_phase(std::span<const Map> frames, const Mask& mask, const std::vector<std::size_t>& pix,
               const PhaseOptions& o, PhaseResult& r) {
  std::vector<double> phi(pix.size()), b(pix.size());
  const PupilXY xy = pix.empty() ? PupilXY{} : pupil_xy(mask, pix);
  if (o.algorithm == Algorithm::kAia)
    aia(frames, pix, o, r, phi, b);
  else
    tilt_aia(frames, xy, pix, o, r, phi, b);
  const std::vector<FrameShift> sh = r.shifts.empty() ? pistons(r.steps_rad) : r.shifts;
  measure_residual(frames, pix, mask.width, xy, sh, r, phi, b);
  r.reason = fit_problem(o.algorithm, r, o, frames.size());
  r.converged = r.reason.empty();
  for (std::size_t q = 0; q < pix.size(); ++q) {
    r.modulation.v[pix[q]] = b[q];
    r.phase_rad.v[pix[q]] = b[q] > o.min_modulation ? phi[q] : std::nan("");
  }
}

}  // namespace piezoshift::psi::detail
