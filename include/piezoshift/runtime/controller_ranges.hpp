#pragma once
// Every number of the controller's parameters a calibration file holds, with its range, in one
// list (as safety_ranges.hpp is for [safety]), and controller_problem(): the one check a
// controller passes before any loop runs it, whatever the door. The calibration file's reader and
// writer (calibration/calibration_file.hpp) walk the list; the file's loader, `SPA` over GCS
// (host/servo_parameters.hpp), the Python bindings (a controller handed to a bench, an
// experiment or a measurement) and every command that loads a calibration call
// controller_problem(). It lives in runtime, below both calibration and host, so that the GCS
// server runs the same check as the loader without including a module above it. The list is the
// file's order:
//
//   [controller]           kp, ki, kd (per sample, Eq. 7), gains_sample_time_s;
//                          then p, A and kind, which are checked as a whole below
//   [improved]             sample_time_s (required), reference_delay_ticks, correction_ki,
//                          correction_ki_max, correction_boost_error_um, correction_limit_um,
//                          shaper_taps (a list, summing to 1), shaper_rate_um_per_s
//   [improved.channelN]    offset_um, linear_weight (required), thresholds_um, weights (a list
//                          as long as thresholds_um), creep_time_constants_s, creep_gain
//   [fringe_lock]          with [controller] outer = "fringes": gain_per_frame, max_step_* and
//                          max_correction_* (piston_nm, theta_x_urad, theta_y_urad),
//                          max_lost_frames; checked as a whole by control::fringe_lock_problem
//   [travel]               z_max_um, z_min_um: within the stroke (visit_travel_fields)
//
// Beyond each number's range, controller_problem() refuses what would make the stage report
// nonsense, move where it was not asked or the loop unstable:
//   p          a coefficient that is not finite; a slope p'(z) outside kPolynomialSlope over the
//              stroke [0, kStrokeUm] (the twin identifies 1.016, the paper 1.014: p = [0, 0,
//              1000, 0] sent the plate to full stroke for 1 um, p / 1000 moved it 2 nm); or a
//              cubic that does not rise over [-kStrokeUm, 2 kStrokeUm], where the host inverts
//              it for the gauges' positions (host/stage_model.hpp)
//   A          an entry that is not finite, is subnormal (POS? answered -nan) or is outside
//              kMatrixEntry; a row whose sum (the actuator's gauge um per um of plate piston)
//              is outside kMatrixRowSum (the paper's rows: 0.77 to 0.90); or an A whose 2-norm
//              condition number exceeds kMaxMatrixCondition (an all-zero or singular A cannot be
//              inverted for the positions the gauges show)
//   gains      PIDs that are unstable on the nominal inner loop: the plant a gain G (gauge um
//              per um of command) behind the DAQ contract's two ticks of delay, P(z) = G z^-2,
//              with G = kNominalPlantGain; the loop C(z) P(z) must keep a gain margin > 0 dB.
//              The twin's identified small-signal gain is 0.60 to 0.67 (docs/calibration.md),
//              and its amplifier and conditioner attenuate it further at the phase crossover, so
//              a flat 0.7 refuses gains that cannot be stable on this stage, not all that are not:
//              the identified loop's margins (calibration/loop_identification.hpp) say how far a
//              set is from the edge.
//   loop       what the loop itself refuses at its own sample time (control/parameter_check.hpp)
//
// The feedforward's overall piston gain, d S_i / d Z_d = (A 1)_i p'(Z_d), is what moves the
// stage; bounding its two factors bounds it to [0.25, 3] (the paper's: 0.76 to 0.91 over the
// travel). docs/calibration.md derives each band.
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "piezoshift/control/fringe_lock.hpp"
#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/core/bounds.hpp"
#include "piezoshift/design/actuator_params.hpp"

namespace piezoshift::runtime {

//! Largest 2-norm condition number of A a calibration may hold. The paper's A (Eq. 8) has 1.51;
//! a tripod whose A reaches 100 turns 1 nm of gauge noise into up to 100 nm of computed position.
inline constexpr double kMaxMatrixCondition = 100.0;

//! The nominal inner loop's plant gain (header comment): the identified 0.60 to 0.67, rounded up.
inline constexpr double kNominalPlantGain = 0.7;

//! The stage's stroke [um]: the stacks' free stroke at 150 V (Section 2.1, the design's
//! nominal_stroke_um). No plate travel exceeds it: the flexure takes it to 14.6 um (Eq. 1), and
//! a stack at the +10 % of its stroke tolerance to 16.1 um.
inline constexpr double kStrokeUm = design::ActuatorParams{}.nominal_stroke_um;

//! p'(z) over [0, kStrokeUm]: command um per um of displacement (docs/calibration.md).
inline constexpr core::Bounds kPolynomialSlope = core::Bounds::closed(0.5, 2.0);
//! Each row sum of A: gauge um per um of plate piston (docs/calibration.md).
inline constexpr core::Bounds kMatrixRowSum = core::Bounds::closed(0.5, 1.5);
//! Each entry of A (the paper's largest is 0.70; docs/calibration.md).
inline constexpr core::Bounds kMatrixEntry = core::Bounds::closed(-2.0, 2.0);

//! A list of numbers held in a fixed array and a count (the controller holds no heap).
template <class Value, class Count>
struct ListField {
  Value* values;
  Count* count;
  std::size_t capacity;
  //! The list whose count this one shares (weights: thresholds_um), or null.
  const char* same_count_as = nullptr;
};
template <class Value, class Count>
ListField(Value*, Count*, std::size_t) -> ListField<Value, Count>;
template <class Value, class Count>
ListField(Value*, Count*, std::size_t, const char*) -> ListField<Value, Count>;

//! Calls, in the file's order, visit(section, key, field, bounds, note) for each number: field is
//! a double&, a std::size_t& (a whole number) or a ListField (each element within bounds); note
//! is the writer's comment ("" none) or, for a required key, starts with "required". Const or not.
template <class Params, class Visit>
void visit_controller_fields(Params& p, Visit&& visit) {
  using B = core::Bounds;
  visit("controller", "kp", p.gains.kp, B::non_negative(), "per-sample gains, Eq. 7");
  visit("controller", "ki", p.gains.ki, B::non_negative(), "");
  visit("controller", "kd", p.gains.kd, B::non_negative(), "");
  visit("controller", "gains_sample_time_s", p.gains_sample_time_s, B::positive(), "");
}

//! [improved]'s numbers, as visit_controller_fields.
template <class Improved, class Visit>
void visit_improved_fields(Improved& im, Visit&& visit) {
  using B = core::Bounds;
  visit("improved", "sample_time_s", im.sample_time_s, B::positive(),
        "required when kind = \"improved\"");
  visit("improved", "reference_delay_ticks", im.reference_delay_ticks,
        B::closed(0.0, static_cast<double>(control::kMaxReferenceDelayTicks)), "");
  visit("improved", "correction_ki", im.correction_ki, B::closed(0.0, 1.0),
        "per-sample at sample_time_s");
  visit("improved", "correction_ki_max", im.correction_ki_max, B::closed(0.0, 1.0), "");
  visit("improved", "correction_boost_error_um", im.correction_boost_error_um, B::non_negative(),
        "");
  visit("improved", "correction_limit_um", im.correction_limit_um, B::positive(), "");
  visit("improved", "shaper_taps",
        ListField{im.shaper.weight.data(), &im.shaper.taps, control::kMaxShaperTaps},
        B::closed(0.0, 1.0), "");
  visit("improved", "shaper_rate_um_per_s", im.shaper.rate_um_per_s, B::positive(), "");
  visit("improved", "command_slew_um_per_s", im.command_slew_um_per_s, B::non_negative(),
        "0: large moves shaped like small ones");
  visit("improved", "slew_approach_um", im.slew_approach_um, B::non_negative(), "");
}

//! One [improved.channelN]'s numbers (section: its name), as visit_controller_fields.
template <class Model, class Visit>
void visit_model_fields(Model& m, std::string_view section, Visit&& visit) {
  using B = core::Bounds;
  visit(section, "offset_um", m.offset_um, B::closed(-100.0, 100.0), "");
  visit(section, "linear_weight", m.linear_weight, B::closed(1e-3, 100.0), "required");
  visit(section, "thresholds_um",
        ListField{m.threshold_um.data(), &m.operators, control::kMaxModelOperators}, B::positive(),
        "");
  visit(section, "weights",
        ListField{m.weight.data(), &m.operators, control::kMaxModelOperators, "thresholds_um"},
        B::closed(0.0, 100.0), "");
  visit(section, "creep_time_constants_s",
        ListField{m.creep_time_constant_s.data(), &m.creep_terms, control::kMaxCreepTerms},
        B::positive(), "");
  visit(section, "creep_gain", m.creep_gain, B::closed(-0.05, 0.05), "");
}

//! [fringe_lock]'s numbers (control/fringe_lock.hpp, whose defaults are the file's), as
//! visit_controller_fields; the axes are piston [nm], theta_x and theta_y [urad].
template <class Lock, class Visit>
void visit_fringe_lock_fields(Lock& p, Visit&& visit) {
  using B = core::Bounds;
  visit("fringe_lock", "gain_per_frame", p.gain_per_frame, B::above(0.0, 1.0), "per camera frame");
  static const std::string kStep[3] = {"max_step_piston_nm", "max_step_theta_x_urad",
                                       "max_step_theta_y_urad"};
  static const std::string kTotal[3] = {"max_correction_piston_nm", "max_correction_theta_x_urad",
                                        "max_correction_theta_y_urad"};
  for (std::size_t a = 0; a < 3; ++a)
    visit("fringe_lock", kStep[a], p.max_step[a], B::above(0.0, 1e6), "one frame's largest");
  for (std::size_t a = 0; a < 3; ++a)
    visit("fringe_lock", kTotal[a], p.max_correction[a], B::above(0.0, 1e6), "");
  visit("fringe_lock", "max_lost_frames", p.max_lost_frames, B::closed(1.0, 100000.0), "");
}

//! [travel]'s numbers, as visit_controller_fields: the travel one move from rest reaches and the
//! lowest Z one move down reaches, both within the stroke (and z_min_um < z_max_um, checked
//! whole by travel_problem).
template <class Value, class Visit>
void visit_travel_fields(Value& z_max_um, Value& z_min_um, Visit&& visit) {
  using B = core::Bounds;
  visit("travel", "z_max_um", z_max_um, B::above(0.0, kStrokeUm), "");
  visit("travel", "z_min_um", z_min_um, B::closed(0.0, kStrokeUm), "");
}

//! The section of channel i (0-based): "improved.channel1" ...
std::string model_section(std::size_t channel);

//! A refusal: the section and key it is about (key empty for a rule over the whole section) and
//! a sentence naming them ("[controller] A: ...").
struct FieldProblem {
  std::string section;
  std::string key;
  std::string why;
  bool empty() const noexcept { return why.empty(); }
};

//! The first problem of params as a calibration for a loop at loop_sample_time_s (see the header
//! comment); empty when there is none. params.sample_time_s is not read: the loop sets it.
FieldProblem controller_field_problem(const control::SemiClosedLoopParams& params,
                                      double loop_sample_time_s);
//! controller_field_problem(...).why: "" when there is none.
std::string controller_problem(const control::SemiClosedLoopParams& params,
                               double loop_sample_time_s);

//! The first problem of a travel ([travel]: each within its range, z_min_um < z_max_um when both
//! are given); empty when there is none.
FieldProblem travel_problem(std::optional<double> z_max_um, std::optional<double> z_min_um);

//! The sample time a calibration is made for when no loop is named: the improved controller's
//! design rate, else the rate the gains were tuned at.
double own_sample_time_s(const control::SemiClosedLoopParams& params);

//! The gain margin (dB) of the PIDs, at params.sample_time_s, on the nominal inner loop (header
//! comment): > 0 when stable there; +infinity when the phase never reaches -180 deg.
double nominal_gain_margin_dB(const control::SemiClosedLoopParams& params);

}  // namespace piezoshift::runtime
