#pragma once
// Rate-independent hysteresis of the piezo stack: a Prandtl-Ishlinskii operator (a weighted sum of
// play operators) from the stack voltage to its normalized free elongation.
//
// Input v in volts, normalized v' = v / v_span (v_span = 150 V, the amplifier's full output).
// N play operators in centred form, thresholds rho_j = (j + 1/2) / N (j = 0..N-1):
//   u_j <- clamp(u_j, v' - rho_j, v')                       (backlash of width rho_j)
//   y    = w0 v' + sum_j w_j u_j
// Every u_j = 0 is the state at 0 V on the lower turning point of the major loop 0 -> v_span -> 0,
// which is where the twin starts. On that loop (with equal w_j = W / N):
//   ascending  y_up(v')   = w0 v' + sum_j w_j max(v' - rho_j, 0)     (convex)
//   descending y_down(v') = w0 v' + sum_j w_j min(v', 1 - rho_j)     (concave)
//   range      y_up(1)    = w0 + W m_h = 1       (normalized: m_h = mean(1 - rho_j) = 1/2)
//   gap        max (y_down - y_up) at v' = 1/2  = W m_1,  m_1 = mean(min(rho_j, 1 - rho_j)) = 1/4
// so the hysteresis H (largest gap over the range, for the full 0 -> 150 -> 0 V loop) fixes
//   W / w0 = H / (m_1 - H m_h),   w0 = 1 / (1 + (W / w0) m_h)      (needs H < m_1 / m_h = 1/2).
// Slopes: w0 = 0.75 right after a reversal, rising to w0 + W = 1.25 at the end of a full stroke
// (for H = 12.5 %); the average over the full stroke is 1.
//
// Source of H: PI piezo tutorial, hysteresis of open-loop stacks "2 % (small signal), widening to
// 10 % to 15 % under large-signal conditions"; the twin's target is 10 to 15 % over 0-150-0 V.
// Cycles smaller than rho_0 v_span (9.4 V with N = 8) see only w0: no hysteresis, the
// small-signal end of that statement.
//
// Real-time safe (update): no heap, no exceptions, no I/O.
#include <array>
#include <cstddef>
#include <cstdint>

namespace piezoshift::plant {

inline constexpr std::size_t kMaxPlayOperators = 32;

struct HysteresisParams {
  //! H: largest vertical gap of the 0-150-0 V loop over its range (PI tutorial: 10 to 15 %)
  double hysteresis_fraction = 0.125;
  //! N play operators (the loop is piecewise linear with N + 1 pieces per branch)
  std::int64_t play_operators = 8;

  bool operator==(const HysteresisParams&) const = default;
};

using PlayState = std::array<double, kMaxPlayOperators>;

class PrandtlIshlinskii {
 public:
  PrandtlIshlinskii() = default;
  //! Throws std::invalid_argument for N outside [1, kMaxPlayOperators], H outside [0, 1/2) or a
  //! non-positive span.
  PrandtlIshlinskii(const HysteresisParams& params, double input_span_V);

  //! One input sample: updates the operators and returns y (1.0 at the top of the major loop).
  double update(PlayState& u, double v) const noexcept {
    const double x = v * inv_span_;
    double y = w0_ * x;
    for (std::size_t j = 0; j < n_; ++j) {
      double uj = u[j];
      const double lo = x - rho_[j];
      uj = uj < lo ? lo : uj;
      uj = uj > x ? x : uj;
      u[j] = uj;
      y += w_[j] * uj;
    }
    return y;
  }

  //! PlaySweep (below) evaluates the same y along a monotone run of inputs in O(1) amortized per
  //! input instead of O(N).
  friend class PlaySweep;

  std::size_t operators() const noexcept { return n_; }
  double linear_weight() const noexcept { return w0_; }      //!< w0
  double operator_weight() const noexcept { return w_[0]; }  //!< w_j = W / N
  double threshold(std::size_t j) const noexcept { return rho_[j]; }

 private:
  std::size_t n_ = 0;
  double inv_span_ = 1.0;
  double w0_ = 1.0;
  std::array<double, kMaxPlayOperators> rho_{};
  std::array<double, kMaxPlayOperators> w_{};
};

//! The same operator along a monotone run of inputs (the amplifier's output within one control
//! period moves monotonically toward its held target, so the twin uses this). On a rising run
//! every u_j = max(u_j0, x - rho_j), so with the breakpoints b_j = u_j0 + rho_j,
//!   sum_j u_j = U_0 + sum_{b_j < x} (x - b_j) = U_0 + k x - B_k      (k: breakpoints passed)
//! and on a falling run u_j = min(u_j0, x), with c_j = u_j0,
//!   sum_j u_j = U_0 - sum_{c_j > x} (c_j - x) = U_0 - C_k + k x;
//! either way y = (w0 + w k) x + w (U_0 - B_k), a line that changes only at a breakpoint.
//! The breakpoints need no sorting: from the all-zero start, every rise (u = max(u, x - rho_j))
//! and fall (u = min(u, x)) keeps u_j non-increasing in j and u_j + rho_j non-decreasing in j
//! (both properties survive max and min with such sequences), so a rising run passes b_0, b_1,
//! ... and a falling run c_0, c_1, ... in index order. Exactly the update() result (to
//! rounding); inputs are forced monotone (a run that turns back by rounding is held at its
//! extreme). commit() writes the final operator states.
class PlaySweep {
 public:
  //! Starts a run at the state u, which must outlive the sweep and is read, not written, until
  //! commit(). rising: the direction of the run.
  PlaySweep(const PrandtlIshlinskii& op, const PlayState& u, bool rising) noexcept
      : op_(op), u_(u), n_(op.n_), rising_(rising) {
    double base = 0.0;
    for (std::size_t j = 0; j < n_; ++j)
      base += u[j];
    // y = slope x + intercept between breakpoints: slope = w0 + w k, intercept = w (U_0 - sum)
    slope_ = op.w0_;
    intercept_ = op.w_[0] * base;
    x_ = rising ? -kHuge : kHuge;
    next_ = breakpoint(0);
  }

  //! y at the next input of the run (inputs in volts, as update()).
  double at(double v) noexcept {
    double x = v * op_.inv_span_;
    if (rising_) {
      x = x < x_ ? x_ : x;
      while (k_ < n_ && x > next_)  // bounded even for an infinite input
        pass();
    } else {
      x = x > x_ ? x_ : x;
      while (k_ < n_ && x < next_)
        pass();
    }
    x_ = x;
    return slope_ * x + intercept_;
  }

  //! Writes the operator states at the run's last input (u must be the state given above).
  void commit(PlayState& u) const noexcept {
    if (x_ == kHuge || x_ == -kHuge)
      return;  // no input in the run
    for (std::size_t j = 0; j < n_; ++j) {
      if (rising_) {
        const double lo = x_ - op_.rho_[j];
        u[j] = u[j] < lo ? lo : u[j];
      } else {
        u[j] = u[j] > x_ ? x_ : u[j];
      }
    }
  }

 private:
  static constexpr double kHuge = 1e300;

  // b_k = u_k + rho_k on a rising run, c_k = u_k on a falling one; beyond the last, never reached.
  double breakpoint(std::size_t k) const noexcept {
    if (k >= n_)
      return rising_ ? kHuge : -kHuge;
    return rising_ ? u_[k] + op_.rho_[k] : u_[k];
  }

  // The input has passed breakpoint k: operator k now moves with it.
  void pass() noexcept {
    const double w = op_.w_[0];
    slope_ += w;
    intercept_ -= w * next_;
    next_ = breakpoint(++k_);
  }

  const PrandtlIshlinskii& op_;
  const PlayState& u_;
  std::size_t n_;
  bool rising_;
  std::size_t k_ = 0;
  double slope_ = 0.0;
  double intercept_ = 0.0;
  double next_ = 0.0;
  double x_ = 0.0;
};

}  // namespace piezoshift::plant
