// `piezoshift run`: the real-time loop (docs/runtime.md) against the twin or a Comedi board, with
// the safety supervisor between controller and DAQ (docs/safety.md) and optional fault injection.
//
// Exit status: 0 the run completed (duration, SIGINT or SIGTERM) without a fault; 3 the safety
// supervisor latched a fault (the outputs were ramped to 0 V); 2 bad input, including a DAQ
// device that cannot be opened; 1 internal error.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "fault_report.hpp"
#include "physics_budget.hpp"
#include "piezoshift/calibration/calibration_file.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/procedures/loop_setup.hpp"
#include "piezoshift/procedures/loop_stack.hpp"
#include "piezoshift/runtime/control_loop.hpp"
#include "piezoshift/runtime/csv_logger.hpp"
#include "piezoshift/runtime/fault_injection.hpp"
#include "piezoshift/runtime/loop_clock.hpp"
#include "piezoshift/runtime/realtime.hpp"
#include "piezoshift/runtime/safety_ranges.hpp"
#include "piezoshift/runtime/sim_backend.hpp"
#include "whole_number.hpp"

namespace piezoshift::app {

namespace {

using namespace piezoshift::runtime;

struct RunOptions {
  double max_physics_steps = plant::kDefaultPhysicsStepBudget;  // the start-up calibration
  std::string daq = "sim";
  double rate_Hz = 1000.0;
  std::string calibration;
  std::string config;
  std::optional<double> step_um;
  std::string profile;
  double duration_s = 0.0;
  std::string log;
  bool json = false;
  std::vector<std::string> faults;
  std::uint64_t seed = 1;
  bool free_run = false;
  int cpu = -1;
  std::optional<std::int64_t> max_overruns;  // absent: the installation's (3 built in)
};

double us(std::int64_t ns) {
  return static_cast<double>(ns) * 1e-3;
}

// One status line on stderr, rewritten a few times a second from a thread of its own (never the
// loop's): time, Z_d, the SGS position, the worst tracking error S - SGS, the supervisor.
class LiveStatus {
 public:
  explicit LiveStatus(const LoopStatus& status) : status_(status), thread_([this] { loop(); }) {}
  ~LiveStatus() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      done_ = true;
    }
    wake_.notify_one();
    thread_.join();
    fmt::print(stderr, "\r\033[K");
    std::fflush(stderr);
  }
  LiveStatus(const LiveStatus&) = delete;
  LiveStatus& operator=(const LiveStatus&) = delete;
  //! Off the loop's CPU, as the fault reporter (fault_report.hpp).
  bool keep_off_cpu(int cpu) { return runtime::keep_off_cpu(thread_, cpu); }

 private:
  void loop() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!wake_.wait_for(lock, std::chrono::milliseconds(250), [this] { return done_; })) {
      if (status_.ticks.load(std::memory_order_relaxed) == 0)
        continue;
      const Vec3 zd = LoopStatus::load_vec(status_.zd_um);
      const Vec3 s = LoopStatus::load_vec(status_.target_um);
      const Vec3 fb = LoopStatus::load_vec(status_.feedback_um);
      double worst = 0.0;
      for (std::size_t i = 0; i < 3; ++i)
        worst = std::max(worst, std::fabs(s[i] - fb[i]));
      const auto reason = static_cast<FaultReason>(status_.fault_reason.load());
      fmt::print(stderr,
                 "\r\033[Kt {:8.2f} s  Z_d {:.3f} {:.3f} {:.3f} um  SGS {:.3f} {:.3f} {:.3f} um  "
                 "error max {:.1f} nm  {}{}",
                 status_.t_s.load(), zd[0], zd[1], zd[2], fb[0], fb[1], fb[2], worst * 1e3,
                 to_string(static_cast<SupervisorState>(status_.state.load())),
                 reason != FaultReason::kNone ? fmt::format(" FAULT {}", to_string(reason)) : "");
      std::fflush(stderr);
    }
  }

  const LoopStatus& status_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool done_ = false;
  std::thread thread_;
};

nlohmann::json vec_json(const Vec3& v) {
  nlohmann::json a = nlohmann::json::array();
  for (double x : v)
    a.push_back(std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr));
  return a;
}

// What a run did, as the JSON summary reports it.
struct RunRecord {
  const RunOptions& options;
  procedures::LoopStack& stack;
  const ControlLoop& loop;
  const LoopResult& result;
  const SafetyLimits& limits;
  const RealtimeReport& realtime;
  const std::vector<std::string>& fault_loads;  //!< the load each fault's report read
};

// The tick the first fault was injected on, when the supervisor's fault came after it.
std::optional<std::uint64_t> injected_before_fault(const RunRecord& run) {
  const FaultInjectingBackend* injector = run.stack.injector();
  const LoopResult& r = run.result;
  const std::uint64_t injected =
      injector ? injector->first_injected_tick() : FaultInjectingBackend::kNotYet;
  if (r.fault_detected && injected != FaultInjectingBackend::kNotYet && r.fault.tick >= injected)
    return injected;
  return std::nullopt;
}

// The tracking error S - SGS the PIDs saw at the end of the controlled part.
Vec3 end_tracking_um(const LoopResult& r) {
  Vec3 tracking{};
  for (std::size_t i = 0; i < 3; ++i)
    tracking[i] = r.end_target_um[i] - r.end_feedback_um[i];
  return tracking;
}

nlohmann::json timing_json(const LoopStats& st) {
  nlohmann::json j;
  j["period_error_p50_us"] = us(st.period_error.percentile_ns(0.5));
  j["period_error_p99_us"] = us(st.period_error.percentile_ns(0.99));
  j["period_error_p999_us"] = us(st.period_error.percentile_ns(0.999));
  j["period_error_max_us"] = us(st.period_error.max_ns());
  j["wake_latency_p50_us"] = us(st.wake_latency.percentile_ns(0.5));
  j["wake_latency_p99_us"] = us(st.wake_latency.percentile_ns(0.99));
  j["wake_latency_p999_us"] = us(st.wake_latency.percentile_ns(0.999));
  j["wake_latency_max_us"] = us(st.wake_latency.max_ns());
  j["compute_time_p50_us"] = us(st.compute.percentile_ns(0.5));
  j["compute_time_p99_us"] = us(st.compute.percentile_ns(0.99));
  j["compute_time_max_us"] = us(st.compute.max_ns());
  j["overruns"] = st.overruns;
  j["max_consecutive_overruns"] = st.max_consecutive_overruns;
  j["skipped_slots"] = st.skipped_slots;
  return j;
}

void add_fault_json(nlohmann::json& j, const RunRecord& run) {
  const LoopResult& r = run.result;
  j["fault_detected"] = r.fault_detected;
  j["fault_reason"] = r.fault_detected ? nlohmann::json(to_string(r.fault.reason)) : nullptr;
  j["fault_tick"] = r.fault_detected ? nlohmann::json(r.fault.tick) : nullptr;
  j["fault_channel"] = r.fault_detected && r.fault.channel >= 0
                           ? nlohmann::json(r.fault.channel + 1)
                           : nlohmann::json(nullptr);
  j["fault_value"] = r.fault_detected ? nlohmann::json(r.fault.value) : nullptr;
  j["fault_limit"] = r.fault_detected ? nlohmann::json(r.fault.limit) : nullptr;
  j["faults_latched"] = faults_json(r.faults, run.fault_loads);
  nlohmann::json injected_list = nlohmann::json::array();
  const FaultInjectingBackend* injector = run.stack.injector();
  for (std::size_t i = 0; injector && i < injector->faults().size(); ++i) {
    const FaultSpec& f = injector->faults()[i];
    const std::uint64_t t = injector->injected_tick(i);
    injected_list.push_back(
        {{"kind", to_string(f.kind)},
         {"time_s", f.time_s},
         {"channel", f.channel >= 0 ? nlohmann::json(f.channel + 1) : nlohmann::json(nullptr)},
         {"injected_tick",
          t != FaultInjectingBackend::kNotYet ? nlohmann::json(t) : nlohmann::json(nullptr)}});
  }
  j["faults_injected"] = injected_list;
  const std::string device_error = run.stack.daq().device_error();
  j["device_error"] = device_error.empty() ? nlohmann::json(nullptr) : nlohmann::json(device_error);
  const std::string unsafe = run.stack.daq().safe_state_error();
  j["outputs_at_0_V"] = unsafe.empty();
  const std::optional<std::uint64_t> injected = injected_before_fault(run);
  j["detect_latency_ticks"] =
      injected ? nlohmann::json(r.fault.tick - *injected) : nlohmann::json(nullptr);
}

// Where the controlled part ended (before the ramp to 0 V): the position the SGS report, the
// tracking error S - SGS the PIDs saw, and on the twin its interferometer.
void add_end_json(nlohmann::json& j, const RunRecord& run) {
  const LoopResult& r = run.result;
  const bool has_end = r.controlled_end_tick > 0;
  const auto or_null = [has_end](const Vec3& v) {
    return has_end ? vec_json(v) : nlohmann::json(nullptr);
  };
  j["final_time_s"] = has_end ? nlohmann::json(static_cast<double>(r.controlled_end_tick) *
                                               static_cast<double>(run.stack.period_ns()) * 1e-9)
                              : nlohmann::json(nullptr);
  j["final_setpoint_um"] = or_null(r.end_zd_um);
  j["final_target_um"] = or_null(r.end_target_um);
  j["final_sgs_um"] = or_null(r.end_feedback_um);
  j["final_tracking_error_um"] = or_null(end_tracking_um(r));
  j["final_interferometer_um"] = or_null(r.end_interferometer_um);
}

nlohmann::json run_json(const RunRecord& run) {
  const RunOptions& o = run.options;
  const LoopResult& r = run.result;
  const RealtimeReport& rt = run.realtime;
  const runtime::CsvLogger* logger = run.stack.logger();
  nlohmann::json j;
  j["daq"] = run.stack.name();
  j["rate_Hz"] = o.rate_Hz;
  j["sample_time_s"] = static_cast<double>(run.stack.period_ns()) * 1e-9;
  j["clock"] = o.free_run ? "free-run" : "realtime";
  j["duration_s"] = o.duration_s;
  j["ticks"] = r.ticks;
  j["stop_reason"] = procedures::stop_reason_text(r);
  j.update(timing_json(run.loop.stats()));
  j["realtime"] = {{"sched_fifo", rt.fifo},
                   {"mlockall", rt.memory_locked},
                   {"cpu", rt.cpu >= 0 ? nlohmann::json(rt.cpu) : nlohmann::json(nullptr)},
                   {"refused", rt.refusals}};
  add_fault_json(j, run);
  j["safety"] = procedures::safety_json(run.limits);
  j["max_output_V"] = r.max_output_V;
  j["min_output_V"] = r.min_output_V;
  j["max_output_slew_V_per_ms"] = r.max_output_slew_V_per_ms;
  add_end_json(j, run);
  j["log"] = {{"path", o.log.empty() ? nlohmann::json(nullptr) : nlohmann::json(o.log)},
              {"records_written", logger ? logger->records_written() : 0},
              {"records_dropped", r.telemetry_dropped},
              {"error", logger && !logger->error().empty() ? nlohmann::json(logger->error())
                                                           : nlohmann::json(nullptr)}};
  return j;
}

void print_run(const RunRecord& run) {
  const RunOptions& o = run.options;
  const LoopResult& r = run.result;
  const LoopStats& st = run.loop.stats();
  fmt::print("run: {} at {} Hz ({} clock), {} ticks, stopped by {}\n", run.stack.name(), o.rate_Hz,
             o.free_run ? "free-running" : "real-time", r.ticks, procedures::stop_reason_text(r));
  fmt::print("period error   p50 {:.1f} us  p99 {:.1f} us  p99.9 {:.1f} us  max {:.1f} us\n",
             us(st.period_error.percentile_ns(0.5)), us(st.period_error.percentile_ns(0.99)),
             us(st.period_error.percentile_ns(0.999)), us(st.period_error.max_ns()));
  fmt::print("compute time   p50 {:.1f} us  p99 {:.1f} us  max {:.1f} us\n",
             us(st.compute.percentile_ns(0.5)), us(st.compute.percentile_ns(0.99)),
             us(st.compute.max_ns()));
  fmt::print("overruns       {} (longest run {})\n", st.overruns, st.max_consecutive_overruns);
  fmt::print("outputs        max {:.3f} V, max slew {:.3f} V/ms\n", r.max_output_V,
             r.max_output_slew_V_per_ms);
  if (r.controlled_end_tick > 0) {
    const Vec3 tracking = end_tracking_um(r);
    double worst_tracking_um = 0.0;
    for (const double e : tracking)
      worst_tracking_um = std::max(worst_tracking_um, std::fabs(e));
    fmt::print(
        "final position Z_d {:.4f} {:.4f} {:.4f} um, SGS {:.4f} {:.4f} {:.4f} um{}\n",
        r.end_zd_um[0], r.end_zd_um[1], r.end_zd_um[2], r.end_feedback_um[0], r.end_feedback_um[1],
        r.end_feedback_um[2],
        std::isfinite(r.end_interferometer_um[0])
            ? fmt::format(", interferometer {:.4f} {:.4f} {:.4f} um", r.end_interferometer_um[0],
                          r.end_interferometer_um[1], r.end_interferometer_um[2])
            : std::string());
    fmt::print("tracking error S - SGS {:+.1f} {:+.1f} {:+.1f} nm (worst {:.1f} nm)\n",
               tracking[0] * 1e3, tracking[1] * 1e3, tracking[2] * 1e3, worst_tracking_um * 1e3);
  }
  if (r.fault_detected) {
    const std::optional<std::uint64_t> injected = injected_before_fault(run);
    for (std::uint32_t i = 0; i < r.faults.kept(); ++i)
      fmt::print(
          "FAULT          {}{}\n",
          describe_fault(r.faults.entries[i], i < run.fault_loads.size() ? run.fault_loads[i] : ""),
          i == 0 && injected ? fmt::format(", {} ticks after injection", r.fault.tick - *injected)
                             : "");
  } else {
    fmt::print("faults         none\n");
  }
  fmt::print("{}", device_error_line(run.stack.daq()));
  if (const runtime::CsvLogger* logger = run.stack.logger()) {
    fmt::print("log            {} ({} records{})\n", o.log, logger->records_written(),
               r.telemetry_dropped ? fmt::format(", {} DROPPED", r.telemetry_dropped) : "");
  }
}

procedures::LoopStackOptions stack_options(const RunOptions& o) {
  procedures::LoopStackOptions so;
  so.daq = o.daq;
  so.rate_Hz = o.rate_Hz;
  so.seed = o.seed;
  so.config_path = o.config;
  so.clock = o.free_run ? procedures::StackClock::kFreeRun : procedures::StackClock::kRealTime;
  so.faults = o.faults;
  so.log = o.log;
  so.log_reports_faults = false;  // run's FaultReporter does, with the value and limit
  return so;
}

int run(const RunOptions& o) {
  procedures::check_loop_rate(o.rate_Hz);
  if (!(o.duration_s > 0.0) || o.duration_s > kMaxRunDurationS)
    throw core::InputError(
        fmt::format("--duration-s {}: must be in (0, {}] s", o.duration_s, kMaxRunDurationS));
  SetpointProfile profile = !o.profile.empty() ? SetpointProfile::load_csv(o.profile)
                                               : SetpointProfile::step(o.step_um.value_or(0.0));
  const runtime::InstallationConfig installation =
      o.config.empty() ? runtime::InstallationConfig{}
                       : runtime::load_installation_config(o.config);
  const config::ProjectConfig& project = installation.project;
  // The stack first: a bad --fault, --daq or device is named before the twin's calibration runs.
  procedures::LoopStack stack(stack_options(o), project);
  const procedures::LoopCalibration cal = procedures::resolve_calibration(
      o.calibration, o.daq, project, o.seed, 1.0 / o.rate_Hz, o.max_physics_steps);
  calibration::refuse_fringe_lock(cal, "run");
  if (o.step_um && cal.travel_z_max_um && *o.step_um > *cal.travel_z_max_um)
    throw core::InputError(
        fmt::format("--step-um {}: beyond the calibrated semi-closed-loop "
                    "travel, {} um ({})",
                    *o.step_um, *cal.travel_z_max_um, cal.source));

  LoopConfig config;
  config.rate_Hz = o.rate_Hz;
  config.duration_s = o.duration_s;
  config.stop_signal = &procedures::g_stop_signal;
  LoopStatus live;
  const bool show_live = ::isatty(STDERR_FILENO) == 1 && !o.free_run;
  config.status = &live;  // the live line's and the fault reports' source
  const SafetyLimits limits = runtime::resolve_overrun_trip(
      procedures::loop_safety_limits(installation.safety, o.max_overruns), stack.sim() != nullptr);
  if (!o.json)
    fmt::print("safety: {}\n", describe(limits));
  ControlLoop loop(config, cal.params, limits, stack.daq(), stack.clock(), std::move(profile),
                   stack.telemetry());

  procedures::StopSignals signals;
  stack.start_logging();  // before the real-time request: the logging thread stays normal
  std::optional<LiveStatus> status_line;  // likewise: it must not inherit the loop's priority
  if (show_live)
    status_line.emplace(live);
  FaultReporter fault_reporter(live);  // each fault on stderr as it latches
  RealtimeReport rt;
  if (stack.clock().real_time())
    rt = procedures::request_realtime_or_warn(o.cpu);
  // Printing and reading /proc there would cost the loop deadlines, as serve's network threads.
  if (rt.cpu >= 0) {
    bool moved = fault_reporter.keep_off_cpu(rt.cpu);
    if (status_line)
      moved = status_line->keep_off_cpu(rt.cpu) && moved;
    if (!moved)
      fmt::print(stderr,
                 "piezoshift: warning: the fault report and status line share CPU {} with the "
                 "loop (no other CPU, or refused)\n",
                 rt.cpu);
  }

  stack.daq().activate();
  const LoopResult r = loop.run();
  status_line.reset();  // clears its line before the summary
  fault_reporter.stop();
  stack.daq().deactivate();
  stack.stop_logging();

  const std::vector<std::string> fault_loads = fault_reporter.loads();
  const RunRecord record{o, stack, loop, r, limits, rt, fault_loads};
  if (o.json)
    fmt::print("{}\n", run_json(record).dump(2));
  else
    print_run(record);
  const runtime::CsvLogger* logger = stack.logger();
  if (logger && !logger->error().empty())
    fmt::print(stderr, "piezoshift: error: log {}: {}\n", o.log, logger->error());
  if (report_unsafe_outputs(stack.daq(), "piezoshift"))
    return kExitFault;
  return r.fault_detected ? kExitFault : 0;
}

}  // namespace

void add_run_command(CLI::App& app, Action& action) {
  auto o = std::make_shared<RunOptions>();
  CLI::App* cmd = app.add_subcommand(
      "run", "Run the real-time loop against the twin or a Comedi DAQ board (docs/runtime.md)");
  cmd->add_option("--daq", o->daq, "sim, or comedi:/dev/comediN (the NI PCI-6229 via Comedi)")
      ->capture_default_str();
  cmd->add_option("--rate-hz", o->rate_Hz, "loop rate, 1000 (the paper) to 10000 Hz")
      ->capture_default_str();
  cmd->add_option("--calibration", o->calibration,
                  "TOML with [controller] kp, ki, kd, gains_sample_time_s, p, A");
  cmd->add_option("--config", o->config,
                  "TOML configuration (configs/paper.toml's sections): the twin's, and what the "
                  "twin calibration without --calibration runs on");
  auto* step = cmd->add_option("--step-um", o->step_um, "step Z_d1 = Z_d2 = Z_d3 to Z (um)");
  auto* prof =
      cmd->add_option("--profile", o->profile,
                      "CSV with t_s and zd_um (or zd1_um, zd2_um, zd3_um), piecewise linear");
  step->excludes(prof);
  prof->excludes(step);
  cmd->add_option("--duration-s", o->duration_s, "controlled time (s); a ramp to 0 V follows")
      ->required();
  cmd->add_option("--log", o->log, "CSV log of every tick (flushed every 0.25 s)");
  cmd->add_flag("--json", o->json, "print the summary as JSON");
  cmd->add_option("--fault", o->faults,
                  "inject KIND@T_S[:CHANNEL] into the twin (sgs-open, sgs-stuck, adc-nan, "
                  "adc-spike, amplifier-fail, actuator-crack, overrun-burst); repeatable");
  add_physics_budget_option(cmd, o->max_physics_steps);
  cmd->add_option("--seed", o->seed, "twin noise seed")
      ->capture_default_str()
      ->check(whole_number(0, kAnyUnsigned));
  cmd->add_flag("--free-run", o->free_run,
                "sim only: simulated clock, as fast as possible (tests, benches)");
  cmd->add_option("--max-overruns", o->max_overruns,
                  "consecutive deadline overruns that trip the supervisor (default 3)")
      ->check(whole_number(1, runtime::kMaxConsecutiveOverruns));
  cmd->add_option("--cpu", o->cpu, "CPU to pin the loop to (-1: the last one, -2: none)")
      ->capture_default_str();
  cmd->callback([&action, o] { action = [o] { return run(*o); }; });
}

}  // namespace piezoshift::app
