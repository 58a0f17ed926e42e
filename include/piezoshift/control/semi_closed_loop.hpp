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
// Real-time safe: no heap, no exceptions, no I/O; every member is noexcept. Templated on the
// scalar type (see vec3.hpp): SemiClosedLoopController is the double one, the firmware runs
// BasicSemiClosedLoopController<float>.
#include <cstddef>
#include <cstdint>

#include "piezoshift/control/cubic_polynomial.hpp"
#include "piezoshift/control/incremental_pid.hpp"
#include "piezoshift/control/signal_scaling.hpp"
#include "piezoshift/control/transmission_matrix.hpp"
#include "piezoshift/control/vec3.hpp"

namespace piezoshift::control {

template <class T>
struct BasicSemiClosedLoopParams {
  T sample_time_s = T(1e-3);        //!< T_s, Section 4: 1 ms
  BasicPidGains<T> gains{};         //!< per-sample gains, valid at gains_sample_time_s
  T gains_sample_time_s = T(1e-3);  //!< the sample time the gains were tuned at (paper: 1 ms)
  T output_min_um = T(0.0);         //!< PID output limits, in um of command (0 V)
  T output_max_um = T(16.0);        //!< 16 um nominal stroke -> 10 V DAQ -> 150 V
  T deadband_um = T(0.0);
  T derivative_filter = T(0.0);  //!< see PidParams
  BasicCubicPolynomial<T> polynomial{};
  BasicTransmissionMatrix<T> matrix{};
  std::array<BasicSignalScaling<T>, kChannels> scaling{};

  //! The PID parameters each channel runs with, gains re-expressed at sample_time_s.
  constexpr BasicPidParams<T> pid_params() const noexcept {
    return BasicPidParams<T>{rescale_gains(gains, gains_sample_time_s, sample_time_s),
                             output_min_um, output_max_um, deadband_um, derivative_filter};
  }
};

using SemiClosedLoopParams = BasicSemiClosedLoopParams<double>;

//! The same parameters in another scalar type, each value rounded once (the firmware's float
//! controller is configured from the host's double parameters this way).
template <class To, class From>
constexpr BasicSemiClosedLoopParams<To> convert(const BasicSemiClosedLoopParams<From>& p) noexcept {
  BasicSemiClosedLoopParams<To> q{};
  q.sample_time_s = static_cast<To>(p.sample_time_s);
  q.gains = {static_cast<To>(p.gains.kp), static_cast<To>(p.gains.ki), static_cast<To>(p.gains.kd)};
  q.gains_sample_time_s = static_cast<To>(p.gains_sample_time_s);
  q.output_min_um = static_cast<To>(p.output_min_um);
  q.output_max_um = static_cast<To>(p.output_max_um);
  q.deadband_um = static_cast<To>(p.deadband_um);
  q.derivative_filter = static_cast<To>(p.derivative_filter);
  q.polynomial = convert<To>(p.polynomial);
  q.matrix = convert<To>(p.matrix);
  for (std::size_t i = 0; i < kChannels; ++i)
    q.scaling[i] = convert<To>(p.scaling[i]);
  return q;
}

template <class T>
struct BasicControllerOutput {
  BasicVec3<T> dac_V{};             //!< the three analog outputs
  BasicVec3<T> target_um{};         //!< S, actuator targets in SGS micrometres
  BasicVec3<T> feedback_um{};       //!< SGS feedback in micrometres
  BasicVec3<T> command_um{};        //!< PID outputs u, in um of command
  std::uint8_t saturated_mask = 0;  //!< bit i set when channel i's PID is at a limit
};

using ControllerOutput = BasicControllerOutput<double>;

template <class T>
class BasicSemiClosedLoopController {
 public:
  using Params = BasicSemiClosedLoopParams<T>;
  using Output = BasicControllerOutput<T>;
  using Vec = BasicVec3<T>;

  constexpr BasicSemiClosedLoopController() noexcept { configure(Params{}); }
  constexpr explicit BasicSemiClosedLoopController(const Params& params) noexcept {
    configure(params);
  }

  //! Replaces the parameters and resets every channel.
  constexpr void configure(const Params& params) noexcept {
    params_ = params;
    const BasicPidParams<T> pid = params.pid_params();
    for (auto& c : pid_) {
      c.set_params(pid);
      c.reset(params.output_min_um);
    }
  }

  //! Outer feedforward only: S = A p(Z_d).
  constexpr Vec actuator_targets(const Vec& zd_um) const noexcept {
    Vec zs{};
    for (std::size_t i = 0; i < kChannels; ++i)
      zs[i] = params_.polynomial(zd_um[i]);
    return params_.matrix(zs);
  }

  //! A full tick from desired point displacements.
  constexpr Output update(const Vec& zd_um, const Vec& sgs_V) noexcept {
    return update_actuators(actuator_targets(zd_um), sgs_V);
  }

  //! A tick from actuator targets in SGS micrometres (inner loop only).
  constexpr Output update_actuators(const Vec& target_um, const Vec& sgs_V) noexcept {
    Output out{};
    out.target_um = target_um;
    for (std::size_t i = 0; i < kChannels; ++i) {
      const BasicSignalScaling<T>& s = params_.scaling[i];
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
  constexpr void reset_to(const Vec& command_um) noexcept {
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

  constexpr const Params& params() const noexcept { return params_; }
  constexpr const BasicIncrementalPid<T>& channel(std::size_t i) const noexcept { return pid_[i]; }

 private:
  Params params_{};
  std::array<BasicIncrementalPid<T>, kChannels> pid_{};
};

using SemiClosedLoopController = BasicSemiClosedLoopController<double>;

}  // namespace piezoshift::control
