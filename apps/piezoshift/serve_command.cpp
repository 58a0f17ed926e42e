// `piezoshift serve`: the real-time loop (docs/runtime.md) driven by GCS 2.0 clients over TCP
// (docs/gcs.md). Two threads: the loop (real-time when granted) and one network thread that owns
// every socket and the GCS interpreter; they meet only in runtime::HostLink's lock-free rings.
//
// Exit status: 0 stopped by SIGINT/SIGTERM or --duration-s; 2 bad input (including an address
// that cannot be bound or a DAQ device that cannot be opened); 1 internal error.
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "loop_setup.hpp"
#include "piezoshift/calibration/calibration_file.hpp"
#include "piezoshift/host/gcs_controller.hpp"
#include "piezoshift/host/line_server.hpp"
#include "piezoshift/host/stage_model.hpp"
#include "piezoshift/io/input_error.hpp"
#include "piezoshift/io/project_config.hpp"
#include "piezoshift/runtime/control_loop.hpp"
#include "piezoshift/runtime/csv_logger.hpp"
#include "piezoshift/runtime/loop_clock.hpp"

namespace piezoshift::app {

namespace {

// Set in g_stop_signal when the network thread fails, so that the loop ramps down.
constexpr int kNetworkFailed = -1;

struct ServeOptions {
  std::string daq = "sim";
  std::string calibration;
  std::string config;
  std::string bind = "127.0.0.1";
  int port = 50000;
  bool allow_remote = false;
  double rate_Hz = 1000.0;
  std::uint64_t seed = 1;
  double duration_s = std::numeric_limits<double>::infinity();
  int max_clients = 8;
  int max_line_bytes = 4096;
  double idle_timeout_s = 600.0;
  double on_target_um = 0.01;
  double on_target_urad = 0.5;
  double settle_s = 0.01;
  std::int64_t max_overruns = 3;
  int cpu = -1;
  std::string log;
  bool json = false;
};

void check(bool ok, const std::string& message) {
  if (!ok)
    throw io::InputError(message);
}

host::StageModel make_stage_model(const ServeOptions& o, const io::ProjectConfig& config,
                                  const control::SemiClosedLoopParams& params,
                                  const LoopCalibration& cal, const runtime::SafetyLimits& safety) {
  try {
    host::StageModelParams mp = host::stage_model_params(config.twin.geometry, params);
    if (cal.travel_z_max_um)
      mp.z_max_um = *cal.travel_z_max_um;
    if (cal.travel_z_min_um)
      mp.z_min_um = *cal.travel_z_min_um;
    mp.amplifier_gain = config.twin.amplifier.gain;
    mp.channel_max_V = safety.output_max_V * mp.amplifier_gain;
    return host::StageModel(mp);
  } catch (const std::invalid_argument& e) {
    throw io::InputError(fmt::format(
        "{}: {}", o.calibration.empty() ? "built-in calibration" : o.calibration, e.what()));
  }
}

int serve(const ServeOptions& o) {
  check_loop_rate(o.rate_Hz);
  check(o.duration_s > 0.0, fmt::format("--duration-s {}: must be > 0 s", o.duration_s));
  check(o.port >= 0 && o.port <= 65535, fmt::format("--port {}: must be 0 to 65535", o.port));
  check(o.max_clients >= 1 && o.max_clients <= 64,
        fmt::format("--max-clients {}: must be 1 to 64", o.max_clients));
  check(o.max_line_bytes >= 64 && o.max_line_bytes <= 1 << 20,
        fmt::format("--max-line-bytes {}: must be 64 to 1048576", o.max_line_bytes));
  check(o.idle_timeout_s > 0.0,
        fmt::format("--idle-timeout-s {}: must be > 0 s", o.idle_timeout_s));
  check(o.on_target_um > 0.0 && std::isfinite(o.on_target_um),
        fmt::format("--on-target-um {}: must be > 0", o.on_target_um));
  check(o.on_target_urad > 0.0 && std::isfinite(o.on_target_urad),
        fmt::format("--on-target-urad {}: must be > 0", o.on_target_urad));
  check(o.settle_s >= 0.0 && o.settle_s <= 10.0,
        fmt::format("--settle-s {}: must be 0 to 10 s", o.settle_s));
  const runtime::SafetyLimits safety = loop_safety_limits(o.max_overruns);

  const io::ProjectConfig config =
      o.config.empty() ? io::ProjectConfig{} : io::load_project_config(o.config);
  const LoopCalibration cal = resolve_calibration(o.calibration, o.daq, config, o.seed);
  const control::SemiClosedLoopParams& params = cal.params;
  const host::StageModel model = make_stage_model(o, config, params, cal, safety);

  ChosenBackend chosen = make_backend(o.daq, config, o.seed, o.rate_Hz);
  runtime::DaqBackend& daq = *chosen.backend;
  daq.configure();  // comedi: names the device it cannot open (exit 2)

  runtime::MonotonicClock clock;
  const double period_s = static_cast<double>(std::llround(1e9 / o.rate_Hz)) * 1e-9;
  runtime::HostLink link;
  host::GcsOptions gopts;
  gopts.on_target_tolerance_um = o.on_target_um;
  gopts.on_target_tolerance_urad = o.on_target_urad;
  gopts.settle_time_s = o.settle_s;
  gopts.identification =
      fmt::format("piezoshift, semi-closed-loop PZT phase shifter ({}), 0, 0.1.0", daq.name());
  host::GcsController gcs(model, link, period_s, gopts);

  host::ListenAddress address;
  address.host = o.bind;
  address.port = static_cast<std::uint16_t>(o.port);
  address.allow_remote = o.allow_remote;
  host::LineServerLimits limits;
  limits.max_clients = static_cast<std::size_t>(o.max_clients);
  limits.max_line_bytes = static_cast<std::size_t>(o.max_line_bytes);
  limits.idle_timeout_s = o.idle_timeout_s;
  host::LineServer server(address, limits, gcs);  // binds now: refusals before the loop starts

  std::unique_ptr<runtime::CsvLogger> logger;
  if (!o.log.empty()) {
    runtime::CsvLoggerOptions lo;
    lo.path = o.log;
    lo.with_truth = chosen.sim != nullptr;
    logger = std::make_unique<runtime::CsvLogger>(lo);
  }

  runtime::LoopConfig lc;
  lc.rate_Hz = o.rate_Hz;
  lc.duration_s = o.duration_s;
  lc.stop_signal = &g_stop_signal;
  lc.stop_when_safe_after_fault = false;  // a client clears faults (SVO)
  lc.host = &link;
  runtime::ControlLoop loop(lc, params, safety, daq, clock, runtime::SetpointProfile::step(0.0),
                            logger ? &logger->ring() : nullptr);

  StopSignals signals;
  if (logger)
    logger->start();
  // The network thread starts before the real-time request, so it stays a normal thread.
  std::exception_ptr network_error;
  std::thread network([&] {
    try {
      server.run(&g_stop_signal);
    } catch (...) {
      network_error = std::current_exception();
      g_stop_signal.store(kNetworkFailed);
    }
  });
  fmt::print("piezoshift serve: GCS 2.0 on {}:{}, loop at {:g} Hz on {}\n", o.bind, server.port(),
             o.rate_Hz, daq.name());
  std::fflush(stdout);
  const runtime::RealtimeReport rt = request_realtime_or_warn(o.cpu);

  daq.activate();
  const runtime::LoopResult r = loop.run();
  daq.deactivate();
  server.stop();
  network.join();
  if (logger)
    logger->stop();
  if (network_error)
    std::rethrow_exception(network_error);

  const host::GcsStats& gs = gcs.stats();
  const host::LineServerStats ns = server.stats();
  const runtime::LoopStats& st = loop.stats();
  std::string stop_reason = runtime::to_string(r.stop_reason);
  if (r.stop_reason == runtime::StopReason::kSignal)
    stop_reason = signal_name(r.signal);
  if (o.json) {
    nlohmann::json j;
    j["daq"] = daq.name();
    j["rate_Hz"] = o.rate_Hz;
    j["ticks"] = r.ticks;
    j["stop_reason"] = stop_reason;
    j["overruns"] = st.overruns;
    j["realtime"] = {{"sched_fifo", rt.fifo}, {"mlockall", rt.memory_locked}};
    j["faults"] = gs.faults;
    j["clients_accepted"] = ns.accepted;
    j["clients_refused"] = ns.refused_max_clients;
    j["clients_dropped_slow"] = ns.disconnected_slow;
    j["clients_dropped_idle"] = ns.disconnected_idle;
    j["command_lines"] = gs.lines;
    j["gcs_errors"] = gs.errors;
    j["loop_commands_applied"] = r.host_commands_applied;
    j["samples_dropped"] = r.host_samples_dropped;
    j["max_output_slew_V_per_ms"] = r.max_output_slew_V_per_ms;
    fmt::print("{}\n", j.dump(2));
  } else {
    fmt::print(
        "serve: {} ticks, stopped by {}; {} clients ({} refused), {} lines, {} GCS errors, {} "
        "faults, {} samples dropped, {} overruns\n",
        r.ticks, stop_reason, ns.accepted, ns.refused_max_clients, gs.lines, gs.errors, gs.faults,
        r.host_samples_dropped, st.overruns);
  }
  return 0;
}

}  // namespace

void add_serve_command(CLI::App& app, Action& action) {
  auto o = std::make_shared<ServeOptions>();
  CLI::App* cmd = app.add_subcommand(
      "serve", "Run the real-time loop under a PI GCS 2.0 compatible TCP server (docs/gcs.md)");
  cmd->add_option("--daq", o->daq, "sim, or comedi:/dev/comediN (the NI PCI-6229 via Comedi)")
      ->capture_default_str();
  cmd->add_option("--calibration", o->calibration,
                  "TOML with [controller] (gains, p, A) and [travel] z_max_um");
  cmd->add_option("--config", o->config, "TOML configuration of the twin and its geometry");
  cmd->add_option("--bind", o->bind, "IPv4 address to listen on")->capture_default_str();
  cmd->add_option("--port", o->port, "TCP port (PI's GCS port is 50000; 0: any free port)")
      ->capture_default_str();
  cmd->add_flag("--allow-remote", o->allow_remote,
                "allow a --bind address other than loopback (GCS has no authentication)");
  cmd->add_option("--rate-hz", o->rate_Hz, "loop rate, 1000 (the paper) to 10000 Hz")
      ->capture_default_str();
  cmd->add_option("--seed", o->seed, "twin noise seed")->capture_default_str();
  cmd->add_option("--duration-s", o->duration_s, "stop after this long (default: at SIGINT/TERM)");
  cmd->add_option("--max-clients", o->max_clients, "clients connected at once")
      ->capture_default_str();
  cmd->add_option("--max-line-bytes", o->max_line_bytes, "longest command line")
      ->capture_default_str();
  cmd->add_option("--idle-timeout-s", o->idle_timeout_s,
                  "disconnect a client silent for this long (s)")
      ->capture_default_str();
  cmd->add_option("--on-target-um", o->on_target_um, "ONT? tolerance of Z (um)")
      ->capture_default_str();
  cmd->add_option("--on-target-urad", o->on_target_urad, "ONT? tolerance of U and V (urad)")
      ->capture_default_str();
  cmd->add_option("--settle-s", o->settle_s, "ONT? needs the tolerance held this long (s)")
      ->capture_default_str();
  cmd->add_option("--max-overruns", o->max_overruns,
                  "consecutive deadline overruns that trip the supervisor")
      ->capture_default_str();
  cmd->add_option("--cpu", o->cpu, "CPU to pin the loop to (-1: the last one, -2: none)")
      ->capture_default_str();
  cmd->add_option("--log", o->log, "CSV log of every tick (flushed every 0.25 s)");
  cmd->add_flag("--json", o->json, "print the summary at exit as JSON");
  cmd->callback([&action, o] { action = [o] { return serve(*o); }; });
}

}  // namespace piezoshift::app
