#pragma once
// The paper's semi-closed-loop controller (Section 3, Figure 5), one tick:
//   Z_S = p(Z_d)                      outer feedforward, cubic linearization (Eq. 8, first)
//   S   = A Z_S                       outer feedforward, transmission matrix (Eq. 8, second)
//   y_i = scaling_i.sgs_to_um(sgs_V_i)                           inner loop feedback (SGS)
//   u_i = PID_i(S_i, y_i)             incremental PID per actuator (Eqs. 6, 7), in um
//   dac_V_i = scaling_i.um_to_dac(u_i)                           DAQ analog output
// Z_d are the desired displacements of the measurement points P1..P3 (um). update_actuators()
// skips the feedforward and takes actuator targets S directly (calibration stages 1 and 2).
//
// Real-time safe: no heap, no exceptions, no I/O; every member is noexcept.
#include <cstdint>

#include "piezoshift/control/cubic_polynomial.hpp"
#include "piezoshift/control/incremental_pid.hpp"
#include "piezoshift/control/signal_scaling.hpp"
#include "piezoshift/control/transmission_matrix.hpp"
#include "piezoshift/control/vec3.hpp"

namespace piezoshift::control {

struct SemiClosedLoopParams {
  double sample_time_s = 1e-3;        //!< T_s, Section 4: 1 ms
  PidGains gains{};                   //!< per-sample gains, valid at gains_sample_time_s
  double gains_sample_time_s = 1e-3;  //!< the sample time the gains were tuned at (paper: 1 ms)
  double output_min_um = 0.0;         //!< PID output limits, in um of command (0 V)
  double output_max_um = 16.0;        //!< 16 um nominal stroke -> 10 V DAQ -> 150 V
  double deadband_um = 0.0;
  double derivative_filter = 0.0;  //!< see PidParams
  CubicPolynomial polynomial{};
  TransmissionMatrix matrix{};
  std::array<SignalScaling, kChannels> scaling{};

  //! The PID parameters each channel runs with, gains re-expressed at sample_time_s.
  constexpr PidParams pid_params() const noexcept {
    return PidParams{rescale_gains(gains, gains_sample_time_s, sample_time_s), output_min_um,
                     output_max_um, deadband_um, derivative_filter};
  }
};

struct ControllerOutput {
  Vec3 dac_V{};                     //!< the three analog outputs
  Vec3 target_um{};                 //!< S, actuator targets in SGS micrometres
  Vec3 feedback_um{};               //!< SGS feedback in micrometres
  Vec3 command_um{};                //!< PID outputs u, in um of command
  std::uint8_t saturated_mask = 0;  //!< bit i set when channel i's PID is at a limit
};

class SemiClosedLoopController {
 public:
  constexpr SemiClosedLoopController() noexcept { configure(SemiClosedLoopParams{}); }
  constexpr explicit SemiClosedLoopController(const SemiClosedLoopParams& params) noexcept {
    configure(params);
  }

  //! Replaces the parameters and resets every channel.
  constexpr void configure(const SemiClosedLoopParams& params) noexcept {
    params_ = params;
    const PidParams pid = params.pid_params();
    for (auto& c : pid_) {
      c.set_params(pid);
      c.reset(params.output_min_um);
    }
  }

  //! Outer feedforward only: S = A p(Z_d).
  constexpr Vec3 actuator_targets(const Vec3& zd_um) const noexcept {
    Vec3 zs{};
    for (std::size_t i = 0; i < kChannels; ++i)
      zs[i] = params_.polynomial(zd_um[i]);
    return params_.matrix(zs);
  }

  //! A full tick from desired point displacements.
  constexpr ControllerOutput update(const Vec3& zd_um, const Vec3& sgs_V) noexcept {
    return update_actuators(actuator_targets(zd_um), sgs_V);
  }

  //! A tick from actuator targets in SGS micrometres (inner loop only).
  constexpr ControllerOutput update_actuators(const Vec3& target_um, const Vec3& sgs_V) noexcept {
    ControllerOutput out{};
    out.target_um = target_um;
    for (std::size_t i = 0; i < kChannels; ++i) {
      const SignalScaling& s = params_.scaling[i];
      out.feedback_um[i] = s.sgs_to_um(sgs_V[i]);
      out.command_um[i] = pid_[i].update(target_um[i], out.feedback_um[i]);
      out.dac_V[i] = s.um_to_dac(out.command_um[i]);
      if (pid_[i].state().saturated)
        out.saturated_mask |= static_cast<std::uint8_t>(1U << i);
    }
    return out;
  }

  constexpr void reset() noexcept {
    for (auto& c : pid_)
      c.reset(params_.output_min_um);
  }
  //! Clears the history and starts each channel from a given command (bumpless hand-over, e.g.
  //! from open loop to closed loop at the voltage already applied).
  constexpr void reset_to(const Vec3& command_um) noexcept {
    for (std::size_t i = 0; i < kChannels; ++i)
      pid_[i].reset(command_um[i]);
  }
  constexpr void set_enabled(bool enabled) noexcept {
    for (auto& c : pid_)
      c.set_enabled(enabled);
  }
  constexpr void hold_integrators(bool held) noexcept {
    for (auto& c : pid_)
      c.hold_integrator(held);
  }

  constexpr const SemiClosedLoopParams& params() const noexcept { return params_; }
  constexpr const IncrementalPid& channel(std::size_t i) const noexcept { return pid_[i]; }

 private:
  SemiClosedLoopParams params_{};
  std::array<IncrementalPid, kChannels> pid_{};
};

}  // namespace piezoshift::control
