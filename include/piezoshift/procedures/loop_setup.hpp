#pragma once
// Set-up shared by the commands that run the real-time loop (`run`, `serve`, `calibrate --daq`;
// the stack itself: loop_stack.hpp): the loop rate and safety limits from the options, the
// controller's calibration, the SIGINT/SIGTERM handlers that stop the loop through its safe ramp,
// and the real-time request with its one warning.
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "piezoshift/calibration/loop_calibration.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/plant/simulation_cost.hpp"
#include "piezoshift/runtime/control_loop.hpp"
#include "piezoshift/runtime/realtime.hpp"
#include "piezoshift/runtime/safety_ranges.hpp"
#include "piezoshift/runtime/safety_supervisor.hpp"

namespace piezoshift::procedures {

//! Throws core::InputError naming option (the CLI's --rate-hz, Python's rate_Hz) unless
//! 1000 <= rate_Hz <= 10000 (the paper's 1 kHz to the DAQ's practical limit, docs/runtime.md).
void check_loop_rate(double rate_Hz, std::string_view option = "--rate-hz");

//! The installation's limits (a config's [safety], or the built-in ones), with --max-overruns
//! consecutive overruns instead when given; throws core::InputError when that is not in
//! [1, runtime::kMaxConsecutiveOverruns].
runtime::SafetyLimits loop_safety_limits(const runtime::SafetyLimits& installation,
                                         std::optional<std::int64_t> max_overruns);

//! The limits as a JSON object, one member per [safety] key.
nlohmann::json safety_json(const runtime::SafetyLimits& limits);

//! The controller a loop runs with, and where it came from.
using calibration::LoopCalibration;

//! --calibration FILE when given. Otherwise, on the twin (--daq sim), the paper's calibration
//! procedure with the paper's gains run on that twin first (one line on stderr says so: a few
//! hundred simulated seconds, well under a second on an idle machine), so that the controller
//! and the twin agree and the advertised travel is the one measured; on hardware, the paper's
//! own values (Section 4) with a warning, since nothing else is known of the stage. A file of the
//! improved controller calibrated at another rate than loop_sample_time_s is refused (its shaper
//! and correction hold at one rate only).
//! The start-up calibration is refused (InputError) when its estimated cost is above
//! max_physics_steps (--max-physics-steps; rig/procedure_cost.hpp).
LoopCalibration resolve_calibration(const std::string& path, const std::string& daq,
                                    const config::ProjectConfig& config, std::uint64_t seed,
                                    double loop_sample_time_s,
                                    double max_physics_steps = plant::kDefaultPhysicsStepBudget);

//! Set by the handlers StopSignals installs: the signal number, 0 until one arrives.
extern std::atomic<int> g_stop_signal;

//! Installs SIGINT/SIGTERM handlers (setting g_stop_signal, cleared here) for its lifetime and
//! restores the old ones.
class StopSignals {
 public:
  StopSignals();
  ~StopSignals();
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;

 private:
  struct Saved;
  std::unique_ptr<Saved> saved_;
};

//! Why a loop stopped, for its summary: "duration", "fault", or the signal ("SIGINT", "SIGTERM",
//! "signal").
std::string stop_reason_text(const runtime::LoopResult& result);

//! Asks for real-time treatment of the calling thread (runtime/realtime.hpp) and prints one
//! warning naming what was refused.
runtime::RealtimeReport request_realtime_or_warn(int cpu);

}  // namespace piezoshift::procedures
