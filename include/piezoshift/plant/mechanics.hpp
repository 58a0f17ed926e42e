#pragma once
// Linear structural dynamics of the three legs carrying the rigid top plate, discretized exactly.
//
// Coordinates: x_i, the displacement of leg i's mechanism output, which is where the plate is
// bolted (rigid joint), in um. Equations of motion (SI inside, x in um):
//   M x'' + C x' + K x = 1e6 F                         F [N], the forces the stacks apply
//   M = m_leg I + T^-T M_p T^-1                        legs' masses plus the plate's, through
//                                                      x = T q, q = (Z, theta_x, theta_y) at O,
//                                                      T rows [1, y_i, -x_i] (leg positions, m)
//   K = (k_m + k_s) I                                  mechanism in parallel with stack + contact
//   M_p = diag(m_p, I_x, I_y)                          plate mass and inertia about O
// Modal form: K phi = w^2 M phi, Phi^T M Phi = I, x = Phi eta,
//   eta_r'' + 2 zeta w_r eta_r' + w_r^2 eta_r = u_r,   u = 1e6 Phi^T F
// and each mode is advanced exactly for a force held over the step h (zero-order hold):
//   [eta; eta']_{n+1} = A_r [eta; eta']_n + B_r u_r
//   A_r = e^{-s h} [[c + (s/wd) sn, sn / wd], [-(w^2/wd) sn, c - (s/wd) sn]],
//         s = zeta w, wd = w sqrt(1 - zeta^2), c = cos(wd h), sn = sin(wd h)
//   B_r = [(1 - A_r11) / w^2, A_r12]
// which is exact for any h (no forward Euler), so the step is set by the inputs, not stability.
// Modal damping: every mode gets the same ratio zeta (see MechanicsParams).
//
// Real-time safe (step, displacement): no heap, no exceptions, no I/O.
#include <array>
#include <cstddef>

#include <Eigen/Core>

namespace piezoshift::plant {

struct MechanicsParams {
  //! Damping ratio of the mechanism alone (one monolithic wire-EDM 45-steel part, no joints):
  //! material damping of steel only, loss factor ~1e-3 to 1e-2, so zeta = eta / 2 = 0.005.
  double mechanism_damping_ratio = 0.005;
  //! Damping ratio of every mode of the assembly (stacks, contacts, bolted plate). Soft PZT has a
  //! mechanical quality factor of ~50 to 100 (zeta 0.005 to 0.01) and the stacks carry most of
  //! the strain energy of these modes; the ball contacts and bolted joints add friction. 0.02 is
  //! the middle of the 0.01 to 0.03 this suggests: "lightly damped", as flexure stages are.
  //! (The paper's loop is sensitive to it: docs/twin.md, "Closed loop".)
  double modal_damping_ratio = 0.02;

  bool operator==(const MechanicsParams&) const = default;
};

using MechanicsState = std::array<double, 6>;  //!< (eta_r, eta_r') for r = 0, 1, 2

class LinearMechanics {
 public:
  LinearMechanics() = default;
  //! M [kg] and K [N/m] symmetric positive definite; throws std::invalid_argument otherwise, or
  //! for zeta outside [0, 1) or a non-positive step.
  LinearMechanics(const Eigen::Matrix3d& mass_kg, const Eigen::Matrix3d& stiffness_N_per_m,
                  double damping_ratio, double step_s);

  //! One step of h with the forces F [N] held. (Written out: this is the twin's innermost loop;
  //! each mode's two updates are alike on adjacent data, so the compiler pairs them.)
  void step(MechanicsState& s, const std::array<double, 3>& force_N) const noexcept {
    const double f0 = force_N[0], f1 = force_N[1], f2 = force_N[2];
    const double u[3] = {in_[0][0] * f0 + in_[0][1] * f1 + in_[0][2] * f2,
                         in_[1][0] * f0 + in_[1][1] * f1 + in_[1][2] * f2,
                         in_[2][0] * f0 + in_[2][1] * f1 + in_[2][2] * f2};
    const double q0 = s[0], v0 = s[1], q1 = s[2], v1 = s[3], q2 = s[4], v2 = s[5];
    const Mode &m0 = mode_[0], &m1 = mode_[1], &m2 = mode_[2];
    s[0] = m0.by_q[0] * q0 + m0.by_v[0] * v0 + m0.by_u[0] * u[0];
    s[1] = m0.by_q[1] * q0 + m0.by_v[1] * v0 + m0.by_u[1] * u[0];
    s[2] = m1.by_q[0] * q1 + m1.by_v[0] * v1 + m1.by_u[0] * u[1];
    s[3] = m1.by_q[1] * q1 + m1.by_v[1] * v1 + m1.by_u[1] * u[1];
    s[4] = m2.by_q[0] * q2 + m2.by_v[0] * v2 + m2.by_u[0] * u[2];
    s[5] = m2.by_q[1] * q2 + m2.by_v[1] * v2 + m2.by_u[1] * u[2];
  }

  //! x = Phi eta [um].
  std::array<double, 3> displacement_um(const MechanicsState& s) const noexcept {
    return {out_[0][0] * s[0] + out_[0][1] * s[2] + out_[0][2] * s[4],
            out_[1][0] * s[0] + out_[1][1] * s[2] + out_[1][2] * s[4],
            out_[2][0] * s[0] + out_[2][1] * s[2] + out_[2][2] * s[4]};
  }

  //! x' = Phi eta' [um/s].
  std::array<double, 3> velocity_um_per_s(const MechanicsState& s) const noexcept {
    std::array<double, 3> v{};
    for (std::size_t i = 0; i < 3; ++i)
      v[i] = out_[i][0] * s[1] + out_[i][1] * s[3] + out_[i][2] * s[5];
    return v;
  }

  //! Undamped natural frequencies w_r / (2 pi), ascending [Hz].
  const std::array<double, 3>& natural_frequencies_Hz() const noexcept { return f_; }
  //! Mode shapes (columns of Phi, mass-normalized, in um per modal unit).
  Eigen::Matrix3d mode_shapes() const;

 private:
  std::array<std::array<double, 3>, 3> in_{};   // 1e6 Phi^T
  std::array<std::array<double, 3>, 3> out_{};  // Phi
  // [q; v]_{n+1} = by_q q_n + by_v v_n + by_u u_n: the columns of A_r and B_r
  struct Mode {
    std::array<double, 2> by_q{}, by_v{}, by_u{};
  };
  std::array<Mode, 3> mode_{};
  std::array<double, 3> f_{};
};

}  // namespace piezoshift::plant
