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
// The improved controller (kind = kImproved, docs/control.md) keeps the feedforward S = A p(Z_d)
// and replaces the PID of each channel by
//   r   = shaper(S_i)                  rate limit at the amplifier's slew, mode-cancelling taps
//   e   = r(k - D) - y                 the model's error, D = the loop's delay
//   c  += ki_e e, |c| <= limit          slow integral correction; ki_e = ki, raised in proportion
//                                       to |e| above boost_error (up to ki_max) so large model
//                                       errors go fast while the gauges' noise stays out
//   t   = r + c, kept within what the model reaches now with the command inside its headroom
//         (a reference governor: near the end of the stroke the stage waits for its creep with
//         the command just short of the rail, and the channel reports itself saturated)
//   u   = model_i^-1(t)                inverse hysteresis-creep model (hysteresis_creep_model.hpp)
// so a set-point change is made by the model at once and the gauges' noise enters only through
// the slow correction (docs/control.md). A large move (more than 2 slew_approach_um away, when
// command_slew_um_per_s > 0) is made instead by the command stepping by the slew limit each tick
// towards model^-1(S_i + c), unshaped: a DAQ step of the full slew keeps the current-limited
// amplifier slewing through the tick, where smaller shaped steps make it slew and pause every
// tick, which rings the plate's mode; slew_approach_um before the target the shaper takes over
// from where the slew left (docs/control.md, "Large moves").
//
// Real-time safe: no heap, no exceptions, no I/O; every member is noexcept. Templated on the
// scalar type (see vec3.hpp): SemiClosedLoopController is the double one, the firmware runs
// BasicSemiClosedLoopController<float>.
#include <cstddef>
#include <cstdint>

#include "piezoshift/control/cubic_polynomial.hpp"
#include "piezoshift/control/hysteresis_creep_model.hpp"
#include "piezoshift/control/incremental_pid.hpp"
#include "piezoshift/control/setpoint_shaper.hpp"
#include "piezoshift/control/signal_scaling.hpp"
#include "piezoshift/control/transmission_matrix.hpp"
#include "piezoshift/control/vec3.hpp"

namespace piezoshift::control {

enum class ControllerKind : std::uint8_t {
  kPaper,     //!< the paper's PIDs (Eqs. 6, 7)
  kImproved,  //!< model inverse, shaping and a slow correction
};

inline constexpr std::size_t kMaxReferenceDelayTicks = 8;

//! The improved controller's parts (identified by calibration/improved_calibration.hpp).
template <class T>
struct BasicImprovedParams {
  //! The sample time the shaper's taps and the correction's gains were designed at; the loop
  //! refuses to run them at another (runtime/control_cycle.cpp).
  T sample_time_s = T(1e-3);
  std::array<BasicHysteresisCreepParams<T>, kChannels> model{};
  BasicShaperParams<T> shaper{};
  //! The correction's per-sample integral gain at sample_time_s (not rescaled: designed per rate).
  T correction_ki = T(0.03);
  T correction_ki_max = T(0.3);           //!< the raised gain's ceiling (stable with D = 2 ticks)
  T correction_boost_error_um = T(0.02);  //!< errors beyond this raise the gain

  T correction_limit_um = T(2);  //!< |c| at most this (SGS um): the model's error, not a move
  std::size_t reference_delay_ticks = 2;  //!< D, from command to the gauges' response
  //! The command range kept in reserve at each end, as a fraction of the range: the governor
  //! holds the target within what the model reaches inside it.
  T headroom_fraction = T(0.001);
  //! Large moves at the slew limit (0: off, the shaper makes every move): a move of more than
  //! twice slew_approach_um is made by the command stepping this fast (um of command per second,
  //! at most what the supervisor passes) until the target is slew_approach_um away, then the
  //! shaper makes the rest (docs/control.md, "Large moves").
  T command_slew_um_per_s = T(0);
  T slew_approach_um = T(1);  //!< SGS um
};

using ImprovedParams = BasicImprovedParams<double>;

template <class To, class From>
constexpr BasicImprovedParams<To> convert(const BasicImprovedParams<From>& p) noexcept {
  BasicImprovedParams<To> q{};
  q.sample_time_s = static_cast<To>(p.sample_time_s);
  for (std::size_t i = 0; i < kChannels; ++i)
    q.model[i] = convert<To>(p.model[i]);
  q.shaper = convert<To>(p.shaper);
  q.correction_ki = static_cast<To>(p.correction_ki);
  q.correction_ki_max = static_cast<To>(p.correction_ki_max);
  q.correction_boost_error_um = static_cast<To>(p.correction_boost_error_um);
  q.correction_limit_um = static_cast<To>(p.correction_limit_um);
  q.reference_delay_ticks = p.reference_delay_ticks;
  q.headroom_fraction = static_cast<To>(p.headroom_fraction);
  q.command_slew_um_per_s = static_cast<To>(p.command_slew_um_per_s);
  q.slew_approach_um = static_cast<To>(p.slew_approach_um);
  return q;
}

template <class T>
struct BasicSemiClosedLoopParams {
  ControllerKind kind = ControllerKind::kPaper;
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
  BasicImprovedParams<T> improved{};  //!< used when kind == kImproved

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
  q.kind = p.kind;
  q.improved = convert<To>(p.improved);
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
    const BasicImprovedParams<T>& im = params.improved;
    delay_ = im.reference_delay_ticks < kMaxReferenceDelayTicks ? im.reference_delay_ticks
                                                                : kMaxReferenceDelayTicks;
    for (std::size_t i = 0; i < kChannels; ++i) {
      model_[i].configure(im.model[i], params.sample_time_s);
      shaper_[i].configure(im.shaper, params.sample_time_s);
    }
    reset_improved(filled<T>(params.output_min_um));
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
    if (params_.kind == ControllerKind::kImproved)
      return update_improved(target_um, sgs_V);
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
    reset_improved(filled<T>(params_.output_min_um));
  }
  //! Clears the history and starts each channel from a given command (bumpless hand-over, e.g.
  //! from open loop to closed loop at the voltage already applied).
  constexpr void reset_to(const Vec& command_um) noexcept {
    for (std::size_t i = 0; i < kChannels; ++i)
      pid_[i].reset(command_um[i]);
    reset_improved(command_um);
  }
  constexpr void set_enabled(bool enabled) noexcept {
    for (auto& c : pid_)
      c.set_enabled(enabled);
    enabled_ = enabled;
  }
  constexpr void hold_integrators(bool held) noexcept {
    for (auto& c : pid_)
      c.hold_integrator(held);
    correction_held_ = held;
  }

  constexpr const Params& params() const noexcept { return params_; }
  constexpr const BasicIncrementalPid<T>& channel(std::size_t i) const noexcept { return pid_[i]; }
  //! The improved controller's model of channel i (its state follows the commands sent).
  constexpr const BasicHysteresisCreepModel<T>& model(std::size_t i) const noexcept {
    return model_[i];
  }

 private:
  constexpr Output update_improved(const Vec& target_um, const Vec& sgs_V) noexcept {
    Output out{};
    out.target_um = target_um;
    const BasicImprovedParams<T>& im = params_.improved;
    const T slew = im.command_slew_um_per_s * params_.sample_time_s;
    for (std::size_t i = 0; i < kChannels; ++i) {
      const BasicSignalScaling<T>& s = params_.scaling[i];
      out.feedback_um[i] = s.sgs_to_um(sgs_V[i]);
      if (slew > T(0) && enabled_ && !slewing_[i] &&
          shaper_[i].distance(target_um[i]) > T(2) * im.slew_approach_um)
        slewing_[i] = true;
      const T r = slewing_[i] ? shaper_[i].output() : shaper_[i].update(target_um[i]);
      auto& hist = reference_[i];
      for (std::size_t k = kMaxReferenceDelayTicks; k > 0; --k)
        hist[k] = hist[k - 1];
      hist[0] = r;
      T e = hist[delay_] - out.feedback_um[i];
      if (!(e == e))
        e = T(0);  // a NaN reading never reaches the correction (the supervisor reports it)
      const T ae = e < T(0) ? -e : e;
      T ki = im.correction_ki;
      // No boost while the reference moves (the last D + 2 ticks): a fast move's errors are the
      // plant's lag, not the model's, and boosting on them winds the correction up.
      const T moved =
          hist[0] -
          hist[delay_ + 2 <= kMaxReferenceDelayTicks ? delay_ + 2 : kMaxReferenceDelayTicks];
      const bool moving = (moved < T(0) ? -moved : moved) > im.correction_boost_error_um;
      if (!moving && ae > im.correction_boost_error_um && im.correction_boost_error_um > T(0)) {
        ki = ki * ae / im.correction_boost_error_um;
        ki = ki > im.correction_ki_max ? im.correction_ki_max : ki;
      }
      T& corr = correction_[i];
      // The governor: the target within what the model reaches now with the command inside its
      // headroom below the top (at the bottom, 0 V is a rest, not a limit to wait at). No
      // integration while held, nor further into a limit the target sits at.
      const T room = im.headroom_fraction * (params_.output_max_um - params_.output_min_um);
      const T y_top = model_[i].predict(params_.output_max_um - room);
      const bool at_top = governed_[i] > 0;
      const bool at_bottom = governed_[i] < 0;
      if (!correction_held_ && !(at_top && e > T(0)) && !(at_bottom && e < T(0)))
        corr += ki * e;
      const T limit = im.correction_limit_um;
      const bool corr_limited = corr > limit || corr < -limit;
      corr = corr > limit ? limit : (corr < -limit ? -limit : corr);
      T target = (slewing_[i] ? target_um[i] : r) + corr;
      governed_[i] = 0;
      if (target > y_top) {
        target = y_top;
        governed_[i] = 1;
      }
      T u = T(0);
      bool clamped = governed_[i] != 0;
      if (enabled_) {
        bool at_rail = false;
        u = model_[i].inverse(target, params_.output_min_um, params_.output_max_um, at_rail);
        if (at_rail && !(u > params_.output_min_um))
          governed_[i] = -1;
        clamped = clamped || at_rail;
        if (slewing_[i])
          u = slew_step(i, u, slew, target_um[i], corr, hist[0]);
      } else {
        corr = T(0);
        slewing_[i] = false;
      }
      model_[i].commit(u);
      out.command_um[i] = u;
      out.dac_V[i] = s.um_to_dac(u);
      if (clamped || corr_limited)
        out.saturated_mask |= static_cast<std::uint8_t>(1U << i);
    }
    return out;
  }

  // One tick of a large move: the command at most slew from the last one towards u (the command
  // for the whole move). The reference (and the shaper's state) is what the model reads with the
  // command sent, so the correction sees the model's error only, not the move. The slew ends once
  // the model reads within slew_approach_um of the target (after a whole slew step: a partial one
  // that stops at exactly that distance rang the plate more, docs/compare.md), or where the
  // command arrives; the shaper goes on from there.
  constexpr T slew_step(std::size_t i, T u, T slew, T target, T corr, T& reference) noexcept {
    const T u0 = model_[i].command_um();
    const T du = u - u0;
    const bool limited = du > slew || du < -slew;
    if (limited)
      u = du > T(0) ? u0 + slew : u0 - slew;
    const T r = limited ? model_[i].predict(u) - corr : target;
    const T left = target - r;
    slewing_[i] = limited && (left < T(0) ? -left : left) > params_.improved.slew_approach_um;
    shaper_[i].reset(r);
    reference = r;
    return u;
  }

  // The models start from the commands held (history unknown: a rising branch), the shapers and
  // the reference delay lines from what the models read there, the corrections from 0.
  constexpr void reset_improved(const Vec& command_um) noexcept {
    for (std::size_t i = 0; i < kChannels; ++i) {
      model_[i].reset_to(command_um[i]);
      const T y = model_[i].output();
      shaper_[i].reset(y);
      reference_[i].fill(y);
      correction_[i] = T(0);
      governed_[i] = 0;
      slewing_[i] = false;
    }
  }

  Params params_{};
  std::array<BasicIncrementalPid<T>, kChannels> pid_{};
  std::array<BasicHysteresisCreepModel<T>, kChannels> model_{};
  std::array<BasicSetpointShaper<T>, kChannels> shaper_{};
  Vec correction_{};  //!< c per channel (SGS um)
  //! +1: the target held below the top by the governor; -1: the command at its lower rail.
  std::array<int, kChannels> governed_{};
  std::array<bool, kChannels> slewing_{};  //!< a large move slewing (command_slew_um_per_s)
  bool enabled_ = true;
  bool correction_held_ = false;
  std::array<std::array<T, kMaxReferenceDelayTicks + 1>, kChannels> reference_{};
  std::size_t delay_ = 0;
};

using SemiClosedLoopController = BasicSemiClosedLoopController<double>;

}  // namespace piezoshift::control
