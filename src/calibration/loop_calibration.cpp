#include "piezoshift/calibration/loop_calibration.hpp"

#include <fmt/core.h>

#include "piezoshift/calibration/calibration_cost.hpp"
#include "piezoshift/calibration/calibration_file.hpp"
#include "piezoshift/calibration/calibration_procedure.hpp"
#include "piezoshift/control/parameter_check.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/runtime/controller_ranges.hpp"

namespace piezoshift::calibration {

void check_at_loop_rate(const control::SemiClosedLoopParams& params, double loop_sample_time_s,
                        const std::string& source) {
  // The loop's own rule (control::params_problem, which the loop applies again when it takes
  // the set), checked here so that the refusal names the source.
  control::SemiClosedLoopParams at_loop = params;
  at_loop.sample_time_s = loop_sample_time_s;
  if (control::params_problem(at_loop, loop_sample_time_s) == control::ParamsProblem::kImprovedRate)
    throw core::InputError(fmt::format(
        "{}: [improved] sample_time_s = {} s, but the loop runs at {} s ({} Hz): calibrate the "
        "improved controller at the loop's rate",
        source, params.improved.sample_time_s, loop_sample_time_s, 1.0 / loop_sample_time_s));
  // Checked at its own rate when it was made; the gains are rescaled to the loop's, where they
  // must be stable too.
  if (const std::string why = runtime::controller_problem(params, loop_sample_time_s); !why.empty())
    throw core::InputError(
        fmt::format("{} at the loop's {} Hz: {}", source, 1.0 / loop_sample_time_s, why));
}

LoopCalibration load_loop_calibration(const std::string& path, double loop_sample_time_s) {
  LoopCalibration c;
  c.params = load_calibration_file(path, &c.travel_z_max_um, &c.travel_z_min_um, &c.fringe_lock);
  check_at_loop_rate(c.params, loop_sample_time_s, path);
  c.source = path;
  return c;
}

void refuse_fringe_lock(const LoopCalibration& c, const std::string& command) {
  if (c.fringe_lock)
    throw core::InputError(fmt::format(
        "{}: [controller] outer = \"fringes\": `piezoshift {}` runs the semi-closed loop alone; "
        "the fringe lock runs in `piezoshift measure` (on the loop's real-time clock it is not "
        "built: docs/fizeau.md)",
        c.source, command));
}

LoopCalibration startup_calibration(const config::ProjectConfig& config, std::uint64_t seed,
                                    double budget_physics_steps, const std::string& raise_option) {
  const CalibrationOptions startup = CalibrationOptions::paper_gains_only();
  rig::check_procedure_budget("the start-up calibration of the twin (no calibration given)",
                              calibration_cost(startup, config.twin.daq.sample_time_s), config.twin,
                              budget_physics_steps, raise_option);
  const CalibrationWithTravel ct = calibrate_with_travel(config, seed, startup);
  LoopCalibration c;
  c.params = ct.calibration.controller;
  c.travel_z_max_um = ct.travel.single_move_um;
  c.travel_z_min_um = ct.travel.single_move_min_um;
  c.source = fmt::format("the twin's own calibration (paper's procedure, seed {})", seed);
  return c;
}

}  // namespace piezoshift::calibration
