#include "piezoshift/procedures/loop_setup.hpp"

#include <cmath>

#include <csignal>

#include <fmt/core.h>

#include "piezoshift/calibration/calibration_cost.hpp"
#include "piezoshift/calibration/calibration_file.hpp"
#include "piezoshift/calibration/calibration_procedure.hpp"
#include "piezoshift/control/parameter_check.hpp"
#include "piezoshift/core/bounds.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/procedures/physics_budget.hpp"
#include "piezoshift/runtime/controller_ranges.hpp"
#include "piezoshift/runtime/safety_ranges.hpp"

namespace piezoshift::procedures {

std::atomic<int> g_stop_signal{0};

namespace {
extern "C" void on_stop_signal(int signo) {
  g_stop_signal.store(signo, std::memory_order_relaxed);
}
}  // namespace

void check_loop_rate(double rate_Hz, std::string_view option) {
  if (!(rate_Hz >= 1000.0 && rate_Hz <= 10000.0))
    throw core::InputError(
        fmt::format("{} {}: supported rates are 1000 to 10000 Hz", option, rate_Hz));
}

runtime::SafetyLimits loop_safety_limits(const runtime::SafetyLimits& installation,
                                         std::optional<std::int64_t> max_overruns) {
  runtime::SafetyLimits limits = installation;
  if (!max_overruns)
    return limits;
  if (*max_overruns < 1 || *max_overruns > runtime::kMaxConsecutiveOverruns)
    throw core::InputError(fmt::format("--max-overruns {}: must be in [1, {}]", *max_overruns,
                                       runtime::kMaxConsecutiveOverruns));
  limits.max_consecutive_overruns = static_cast<std::uint32_t>(*max_overruns);
  return limits;
}

nlohmann::json safety_json(const runtime::SafetyLimits& limits) {
  nlohmann::json j = nlohmann::json::object();
  runtime::visit_safety_limits(limits, [&](const char*, const char* key, const auto& value,
                                           core::Bounds) { j[key] = value; });
  return j;
}

LoopCalibration resolve_calibration(const std::string& path, const std::string& daq,
                                    const config::ProjectConfig& config, std::uint64_t seed,
                                    double loop_sample_time_s, double max_physics_steps) {
  if (!path.empty())
    return calibration::load_loop_calibration(path, loop_sample_time_s);
  if (daq != "sim") {
    fmt::print(stderr,
               "piezoshift: warning: no --calibration: running with the paper's gains, A and p "
               "(Section 4), which describe the paper's stage, not this one\n");
    LoopCalibration c;
    c.source = "the paper's values (Section 4)";
    return c;
  }
  check_physics_budget(max_physics_steps);
  fmt::print(stderr,
             "piezoshift: no --calibration: calibrating the twin first (the paper's procedure "
             "and gains, seed {})\n",
             seed);
  return calibration::startup_calibration(config, seed, max_physics_steps);
}

struct StopSignals::Saved {
  struct sigaction old_int {};
  struct sigaction old_term {};
};

StopSignals::StopSignals() : saved_(std::make_unique<Saved>()) {
  g_stop_signal.store(0);
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, &saved_->old_int);
  sigaction(SIGTERM, &sa, &saved_->old_term);
}

StopSignals::~StopSignals() {
  sigaction(SIGINT, &saved_->old_int, nullptr);
  sigaction(SIGTERM, &saved_->old_term, nullptr);
}

std::string stop_reason_text(const runtime::LoopResult& result) {
  if (result.stop_reason != runtime::StopReason::kSignal)
    return runtime::to_string(result.stop_reason);
  switch (result.signal) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    default:
      return "signal";
  }
}

runtime::RealtimeReport request_realtime_or_warn(int cpu) {
  runtime::RealtimeRequest req;
  req.cpu = cpu;
  runtime::RealtimeReport rt = runtime::request_realtime(req);
  if (!rt.refusals.empty()) {
    std::string why;
    for (const std::string& r : rt.refusals)
      why += (why.empty() ? "" : "; ") + r;
    fmt::print(stderr,
               "piezoshift: warning: real-time request partly refused ({}); running on with "
               "what was granted, the timing figures will show it\n",
               why);
  }
  return rt;
}

}  // namespace piezoshift::procedures
