#pragma once
// Whether a parameter set is one the semi-closed loop can run, decided before the loop takes it.
// The loop changes its controller between two ticks (runtime::ControlCycle::try_configure) and
// must refuse what it cannot run, never throw: an exception there is std::terminate with the DACs
// holding their last value. The check is what the tick needs to be defined:
//
//   kSampleTime      the loop's sample time, the set's and the gains' are finite and > 0, and the
//                    set's is the loop's (to 1e-9 relative: a period in ns read back in s)
//   kImprovedRate    an improved controller runs at the sample time it was designed at (its
//                    shaper taps and correction gains are per sample and not rescaled), ditto
//   kNotFinite       every gain, limit, coefficient, matrix entry, scaling and model value in use
//                    is a finite number
//   kOutputLimits    output_min_um < output_max_um
//   kScaling         sgs_um_per_V and drive_V_per_um are > 0 (the loop divides by the latter to
//                    restart its PIDs from the outputs it holds; the supervisor requires both);
//                    ControlCycle::try_configure also refuses a scaling other than the loop's:
//                    it is the wiring, which the supervisor was set up with
//   kModelSize       no more shaper taps, play operators or creep terms than the controller
//                    holds, and a reference delay of at most kMaxReferenceDelayTicks
//
// The ranges a calibration file may hold are narrower and belong to its reader
// (calibration/calibration_file.cpp); this is the floor below which the loop cannot run at all.
//
// Real-time safe: no heap, no exceptions, no I/O.
#include <cstdint>

#include "piezoshift/control/semi_closed_loop.hpp"

namespace piezoshift::control {

enum class ParamsProblem : std::uint8_t {
  kNone,
  kSampleTime,
  kImprovedRate,
  kNotFinite,
  kOutputLimits,
  kScaling,
  kModelSize,
  kAbsent,  //!< no parameter set came with the request (a host's configure command without one)
};

//! A sentence for a person; "" for kNone.
constexpr const char* to_string(ParamsProblem p) noexcept {
  switch (p) {
    case ParamsProblem::kNone:
      return "";
    case ParamsProblem::kSampleTime:
      return "a sample time is not a positive number or not the loop's";
    case ParamsProblem::kImprovedRate:
      return "the improved controller was calibrated at another sample time than the loop's: "
             "calibrate it at the loop's rate";
    case ParamsProblem::kNotFinite:
      return "a parameter is not a finite number";
    case ParamsProblem::kOutputLimits:
      return "output_min_um is not below output_max_um";
    case ParamsProblem::kScaling:
      return "a signal scaling (sgs_um_per_V or drive_V_per_um) is not > 0 or not the loop's";
    case ParamsProblem::kModelSize:
      return "more shaper taps, model operators, creep terms or delay ticks than the controller "
             "holds";
    case ParamsProblem::kAbsent:
      return "no parameter set came with the request";
  }
  return "unknown problem";
}

namespace detail {

// Finite without <cmath> (constexpr, and the same on the firmware): inf - inf and NaN - NaN are
// NaN, which compares unequal to 0.
template <class T>
constexpr bool finite(T x) noexcept {
  return x - x == T(0);
}

template <class T>
constexpr bool same_time(T a, T b) noexcept {
  const T tolerance = T(1e-9) * b;
  return a - b <= tolerance && b - a <= tolerance;
}

template <class T, class... Ts>
constexpr bool all_finite(T x, Ts... xs) noexcept {
  return (finite(x) && ... && finite(xs));
}

template <class T>
constexpr bool model_fits(const BasicImprovedParams<T>& im) noexcept {
  if (im.shaper.taps > kMaxShaperTaps || im.reference_delay_ticks > kMaxReferenceDelayTicks)
    return false;
  for (const BasicHysteresisCreepParams<T>& m : im.model)
    if (m.operators > kMaxModelOperators || m.creep_terms > kMaxCreepTerms)
      return false;
  return true;
}

// The values in use only (the counts say how many); model_fits() first.
template <class T>
constexpr bool model_finite(const BasicImprovedParams<T>& im) noexcept {
  bool ok = all_finite(im.sample_time_s, im.correction_ki, im.correction_ki_max,
                       im.correction_boost_error_um, im.correction_limit_um, im.headroom_fraction,
                       im.shaper.rate_um_per_s, im.command_slew_um_per_s, im.slew_approach_um);
  for (std::size_t k = 0; k < im.shaper.taps; ++k)
    ok = ok && finite(im.shaper.weight[k]);
  for (const BasicHysteresisCreepParams<T>& m : im.model) {
    ok = ok && all_finite(m.offset_um, m.linear_weight, m.creep_gain);
    for (std::size_t j = 0; j < m.operators; ++j)
      ok = ok && all_finite(m.threshold_um[j], m.weight[j]);
    for (std::size_t k = 0; k < m.creep_terms; ++k)
      ok = ok && finite(m.creep_time_constant_s[k]);
  }
  return ok;
}

}  // namespace detail

//! The first problem of p for a loop running at loop_sample_time_s (see the header comment).
template <class T>
constexpr ParamsProblem params_problem(const BasicSemiClosedLoopParams<T>& p,
                                       T loop_sample_time_s) noexcept {
  using detail::all_finite;
  if (!all_finite(loop_sample_time_s, p.sample_time_s, p.gains_sample_time_s) ||
      !(loop_sample_time_s > T(0)) || !(p.gains_sample_time_s > T(0)) ||
      !detail::same_time(p.sample_time_s, loop_sample_time_s))
    return ParamsProblem::kSampleTime;
  bool finite = all_finite(p.gains.kp, p.gains.ki, p.gains.kd, p.output_min_um, p.output_max_um,
                           p.deadband_um, p.derivative_filter, p.polynomial.p0, p.polynomial.p1,
                           p.polynomial.p2, p.polynomial.p3);
  for (const auto& row : p.matrix.a)
    for (T v : row)
      finite = finite && detail::finite(v);
  for (const BasicSignalScaling<T>& s : p.scaling)
    finite =
        finite && all_finite(s.sgs_um_per_V, s.sgs_offset_V, s.drive_V_per_um, s.drive_offset_V);
  const bool improved = p.kind == ControllerKind::kImproved;
  if (improved && !detail::model_fits(p.improved))
    return ParamsProblem::kModelSize;
  if (!finite || (improved && !detail::model_finite(p.improved)))
    return ParamsProblem::kNotFinite;
  if (improved && !detail::same_time(p.improved.sample_time_s, p.sample_time_s))
    return ParamsProblem::kImprovedRate;
  if (!(p.output_min_um < p.output_max_um))
    return ParamsProblem::kOutputLimits;
  for (const BasicSignalScaling<T>& s : p.scaling)
    if (!(s.sgs_um_per_V > T(0)) || !(s.drive_V_per_um > T(0)))
      return ParamsProblem::kScaling;
  return ParamsProblem::kNone;
}

}  // namespace piezoshift::control
