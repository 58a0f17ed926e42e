#pragma once
// The controller a loop runs (`run`, `serve`, `simulate`, `measure`, Python's measure): a
// calibration file checked at the loop's rate, or on the twin its start-up calibration.
#include <cstdint>
#include <optional>
#include <string>

#include "piezoshift/config/project_config.hpp"
#include "piezoshift/control/fringe_lock.hpp"
#include "piezoshift/control/semi_closed_loop.hpp"

namespace piezoshift::calibration {

struct LoopCalibration {
  control::SemiClosedLoopParams params;
  std::optional<double> travel_z_max_um;  //!< the travel one move reaches, when known
  std::optional<double> travel_z_min_um;  //!< the lowest Z a move from the top reaches
  std::string source;                     //!< the file, or how it was obtained
  //! The fringe lock the file asks for ([controller] outer = "fringes"); only `measure` runs it
  std::optional<control::FringeLockParams> fringe_lock;
};

//! core::InputError naming the source and command when c asks for the fringe lock, which command
//! does not run (it runs the semi-closed loop alone: say so rather than ignore the file's word).
void refuse_fringe_lock(const LoopCalibration& c, const std::string& command);

//! core::InputError naming source when params cannot run at the loop's rate: an improved
//! controller designed at another rate (its shaper and correction hold at one rate only), or
//! gains that are not stable once rescaled to it (runtime/controller_ranges.hpp).
void check_at_loop_rate(const control::SemiClosedLoopParams& params, double loop_sample_time_s,
                        const std::string& source);

//! The calibration file at path (calibration_file.hpp), checked at the loop's rate.
LoopCalibration load_loop_calibration(const std::string& path, double loop_sample_time_s);

//! The twin calibrated by the paper's procedure with the paper's gains (the quickest calibration)
//! and its travel measured, so that controller and twin agree: what a loop on the twin runs
//! without a calibration file. Its cost is checked first (calibration_cost.hpp): core::InputError
//! above budget_physics_steps, naming the settings and raise_option.
LoopCalibration startup_calibration(const config::ProjectConfig& config, std::uint64_t seed,
                                    double budget_physics_steps,
                                    const std::string& raise_option = "--max-physics-steps");

}  // namespace piezoshift::calibration
