// `piezoshift serve`: the real-time loop (docs/runtime.md) driven by GCS 2.0 clients over TCP
// (docs/gcs.md). Two threads: the loop (real-time when granted) and one network thread that owns
// every socket and the GCS interpreter; they meet only in runtime::HostLink's lock-free rings.
// With --http-port a third, normal thread serves the dashboard (docs/dashboard.md): it reads the
// samples the GCS interpreter drains and sends its controls through it, under one mutex, a
// turn of lines at a time. The loop never takes that mutex nor touches a socket, and once it
// is pinned the network threads leave its CPU (runtime::keep_off_cpu), so no client's work,
// however costly, competes with the loop for its CPU.
//
// Exit status: 0 stopped by SIGINT/SIGTERM or --duration-s; 2 bad input (including an address
// that cannot be bound or a DAQ device that cannot be opened); 1 internal error.
#include <sys/resource.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "command.hpp"
#include "dashboard_page.hpp"
#include "fault_report.hpp"
#include "physics_budget.hpp"
#include "piezoshift/calibration/calibration_file.hpp"
#include "piezoshift/camera/instrument_config.hpp"
#include "piezoshift/camera/make_camera.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/host/dashboard.hpp"
#include "piezoshift/host/gcs_interpreter.hpp"
#include "piezoshift/host/http_server.hpp"
#include "piezoshift/host/line_server.hpp"
#include "piezoshift/host/locked_line_handler.hpp"
#include "piezoshift/host/stage_model.hpp"
#include "piezoshift/instrument/twin_measurement.hpp"
#include "piezoshift/io/input_file.hpp"
#include "piezoshift/procedures/loop_setup.hpp"
#include "piezoshift/procedures/loop_stack.hpp"
#include "piezoshift/procedures/stage_model_setup.hpp"
#include "piezoshift/psi/fizeau_simulation.hpp"
#include "piezoshift/runtime/control_loop.hpp"
#include "piezoshift/runtime/csv_logger.hpp"
#include "piezoshift/runtime/fault_injection.hpp"
#include "piezoshift/runtime/loop_clock.hpp"
#include "piezoshift/runtime/safety_ranges.hpp"
#include "serve_camera.hpp"
#include "whole_number.hpp"

namespace piezoshift::app {

namespace {

// Set in procedures::g_stop_signal when the network thread fails, so that the loop ramps down.
constexpr int kNetworkFailed = -1;

// Set once the loop has run its ramp to 0 V and returned.
std::atomic<bool> g_loop_ramped{false};

// A thread that dies in std::terminate (an exception out of a noexcept function, one no catch
// took) would abort the process with the outputs where they are: the loop, still ticking on
// its own thread, is stopped through its ramp first, for at most 2 s, then the process aborts.
[[noreturn]] void ramp_then_abort() noexcept {
  std::fputs("piezoshift serve: a thread failed (std::terminate); ramping the outputs to 0 V\n",
             stderr);
  procedures::g_stop_signal.store(kNetworkFailed);
  for (int i = 0; i < 200 && !g_loop_ramped.load(); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::abort();
}

struct ServeOptions {
  double max_physics_steps = plant::kDefaultPhysicsStepBudget;  // the start-up calibration
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
  std::string idn;  //!< *IDN?'s answer; empty: host::default_identification
  std::optional<std::int64_t> max_overruns;  // absent: the installation's [safety]
  int cpu = -1;
  std::string log;
  bool json = false;
  std::vector<std::string> faults;
  int http_port = -1;  // -1: no dashboard
  std::string http_bind = "127.0.0.1";
  std::string http_token;
  std::string http_token_file;
  int http_max_clients = 16;
  std::string camera;  // "": none
  std::string surface;
  std::string mask;
};

// The camera of the dashboard's live view and measurements (serve_camera.hpp), opened before the
// loop starts so that a camera that cannot be opened is named at once.
struct CameraSetup {
  std::unique_ptr<camera::Camera> camera;
  std::optional<camera::TwinScene> scene;
  ServeCameraOptions options;
};

void check(bool ok, const std::string& message) {
  if (!ok)
    throw core::InputError(message);
}

// A token file holds one line; it is read as every input file is (a regular file, bounded), so
// /dev/zero or a FIFO is refused at once instead of exhausting memory or hanging the start-up.
constexpr std::uintmax_t kMaxTokenFileBytes = 64u << 10;

// --http-token, or the first line of --http-token-file (without surrounding blanks).
std::string http_token(const ServeOptions& o) {
  check(o.http_token.empty() || o.http_token_file.empty(),
        "--http-token and --http-token-file: give one of them");
  std::string token = o.http_token;
  if (!o.http_token_file.empty()) {
    std::string text;
    try {
      text = io::read_input_file(o.http_token_file, kMaxTokenFileBytes);
    } catch (const core::InputError& e) {
      check(false, fmt::format("--http-token-file: {}", e.what()));
    }
    token = text.substr(0, text.find('\n'));
    const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
    while (!token.empty() && blank(token.back()))
      token.pop_back();
    while (!token.empty() && blank(token.front()))
      token.erase(token.begin());
    check(!token.empty(),
          fmt::format("--http-token-file {}: the first line is empty", o.http_token_file));
  }
  check(token.empty() || token.size() >= 16,
        "--http-token: at least 16 characters (e.g. `openssl rand -hex 16`)");
  return token;
}

void check_serve_options(const ServeOptions& o) {
  procedures::check_loop_rate(o.rate_Hz);
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
  check(o.idn.size() <= 200 && o.idn.find_first_of("\r\n") == std::string::npos,
        "--idn: at most 200 characters, one line");
  check(o.settle_s >= 0.0 && o.settle_s <= 10.0,
        fmt::format("--settle-s {}: must be 0 to 10 s", o.settle_s));
  check(o.http_port >= -1 && o.http_port <= 65535,
        fmt::format("--http-port {}: must be 0 to 65535", o.http_port));
  check(o.http_max_clients >= 1 && o.http_max_clients <= 256,
        fmt::format("--http-max-clients {}: must be 1 to 256", o.http_max_clients));
  // As `measure` refuses them (measure_command.cpp).
  check(o.camera != "twin" || o.daq == "sim",
        fmt::format("--camera twin renders the twin's plate: it needs --daq sim, not {}", o.daq));
  const bool fed_by_twin = o.camera.starts_with("aravis:Fake") && o.daq == "sim";
  check(o.surface.empty() || o.camera == "twin" || fed_by_twin,
        "--surface: the test surface of the twin camera (or of aravis:Fake_1 on --daq sim)");
  check(o.mask.empty() || !o.camera.empty(), "--mask: the pupil of --camera's frames");
  if (!o.surface.empty())
    psi::parse_surface_spec(o.surface);  // refused before the start-up calibration, not after
  check(o.mask.empty() || o.camera != "twin",
        "--mask: the twin camera renders its own pupil and analyses it; --mask is the pupil of "
        "other cameras");
  check(o.camera.empty() || o.http_port >= 0,
        "--camera: the live view and the measurements are the dashboard's; give --http-port");
}

CameraSetup open_camera(const ServeOptions& o, const camera::CameraConfig& cc,
                        const procedures::LoopCalibration& cal) {
  CameraSetup c;
  if (o.camera == "twin" || (o.camera.starts_with("aravis:Fake") && o.daq == "sim"))
    c.scene = instrument::measurement_scene(
        o.surface.empty() ? psi::SurfaceSpec{} : psi::parse_surface_spec(o.surface), cc,
        c.options.sequence, o.seed);
  c.camera = camera::make_camera(o.camera, cc, c.scene ? &*c.scene : nullptr);
  c.options.period_s = 1.0 / o.rate_Hz;
  // A replay's frames are the measurements' own: a live view would use them up.
  c.options.preview = !o.camera.starts_with("files:");
  c.options.mask = o.mask;
  c.options.travel_z_max_um = cal.travel_z_max_um;
  c.options.calibration_source = cal.source;
  return c;
}

procedures::LoopStackOptions stack_options(const ServeOptions& o) {
  procedures::LoopStackOptions so;
  so.daq = o.daq;
  so.rate_Hz = o.rate_Hz;
  so.seed = o.seed;
  so.config_path = o.config;
  so.faults = o.faults;
  so.log = o.log;
  so.log_reports_faults = false;  // serve's FaultReporter does, with the value and limit
  return so;
}

host::GcsOptions gcs_options(const ServeOptions& o, const std::string& daq_name) {
  host::GcsOptions g;
  g.on_target_tolerance_um = o.on_target_um;
  g.on_target_tolerance_urad = o.on_target_urad;
  g.settle_time_s = o.settle_s;
  g.identification = o.idn.empty() ? host::default_identification(daq_name) : o.idn;
  return g;
}

// The network side: the GCS interpreter behind the line server, and with --http-port the
// dashboard behind the HTTP server, sharing the interpreter under one mutex.
class Network {
 public:
  Network(const ServeOptions& o, const host::StageModel& model, runtime::HostLink& link,
          double period_s, const std::string& daq_name, const std::string& token,
          CameraSetup camera)
      : gcs_(model, link, period_s, gcs_options(o, daq_name)), locked_gcs_(gcs_, gcs_mutex_) {
    if (o.http_port >= 0) {
      host::DashboardOptions dopts;
      dopts.loop_rate_Hz = o.rate_Hz;
      dopts.daq_name = daq_name;
      dashboard_ = std::make_unique<host::Dashboard>(gcs_, gcs_mutex_, dashboard_page(), dopts);
      if (camera.camera) {
        camera_ = std::make_unique<ServeCamera>(std::move(camera.camera), std::move(camera.scene),
                                                gcs_, gcs_mutex_, std::move(camera.options));
        dashboard_->set_panel(camera_.get());
      }
      gcs_.set_sample_observer(dashboard_.get());
      host::HttpServerOptions hopts;
      hopts.host = o.http_bind;
      hopts.port = static_cast<std::uint16_t>(o.http_port);
      hopts.token = token;
      hopts.max_clients = static_cast<std::size_t>(o.http_max_clients);
      http_ = std::make_unique<host::HttpServer>(hopts, *dashboard_);  // binds now
    }
    host::ListenAddress address;
    address.host = o.bind;
    address.port = static_cast<std::uint16_t>(o.port);
    address.allow_remote = o.allow_remote;
    host::LineServerLimits limits;
    limits.max_clients = static_cast<std::size_t>(o.max_clients);
    limits.max_line_bytes = static_cast<std::size_t>(o.max_line_bytes);
    limits.idle_timeout_s = o.idle_timeout_s;
    server_ = std::make_unique<host::LineServer>(
        address, limits, dashboard_ ? static_cast<host::LineHandler&>(locked_gcs_) : gcs_);
  }
  ~Network() { stop(); }
  Network(const Network&) = delete;
  Network& operator=(const Network&) = delete;

  // Starts the servers' threads: before the real-time request, so they stay normal threads. A
  // server that fails stops the loop through its ramp (procedures::g_stop_signal); stop() rethrows
  // it.
  void start() {
    if (camera_)
      camera_->start([this](std::exception_ptr e) {
        camera_error_ = std::move(e);
        procedures::g_stop_signal.store(kNetworkFailed);
      });
    line_thread_ = std::thread([this] { serve_until_stopped(*server_, line_error_); });
    if (http_)
      http_thread_ = std::thread([this] {
        // The dashboard yields to the GCS clients when both want the CPU they share (nice 5:
        // scripts/serve-latency's POST flood, p99 7.3-13.8 ms -> 4.3-8.2 ms). Best effort.
        if (::setpriority(PRIO_PROCESS, static_cast<id_t>(::gettid()), 5) != 0) {
        }
        serve_until_stopped(*http_, http_error_);
      });
  }
  // Stops and joins both servers, then rethrows the first failure of either.
  void stop() {
    server_->stop();
    if (line_thread_.joinable())
      line_thread_.join();
    if (http_) {
      http_->stop();
      if (http_thread_.joinable())
        http_thread_.join();
    }
    if (camera_)
      camera_->stop();  // after the threads that hand it samples and requests
  }
  void rethrow_failure() const {
    if (line_error_)
      std::rethrow_exception(line_error_);
    if (http_error_)
      std::rethrow_exception(http_error_);
    if (camera_error_)
      std::rethrow_exception(camera_error_);
  }

  // Moves the servers' threads off the loop's CPU; false when there is no other CPU.
  bool keep_off_cpu(int cpu) {
    bool moved = runtime::keep_off_cpu(line_thread_, cpu);
    if (http_thread_.joinable())
      moved = runtime::keep_off_cpu(http_thread_, cpu) && moved;
    if (camera_ && camera_->thread().joinable())
      moved = runtime::keep_off_cpu(camera_->thread(), cpu) && moved;
    return moved;
  }

  const host::GcsInterpreter& gcs() const { return gcs_; }
  host::Dashboard* dashboard() { return dashboard_.get(); }
  const host::LineServer& server() const { return *server_; }
  const host::HttpServer* http() const { return http_.get(); }

 private:
  template <typename Server>
  static void serve_until_stopped(Server& server, std::exception_ptr& error) {
    try {
      server.run(&procedures::g_stop_signal);
    } catch (...) {
      error = std::current_exception();
      procedures::g_stop_signal.store(kNetworkFailed);
    }
  }

  host::GcsInterpreter gcs_;
  std::mutex gcs_mutex_;
  host::LockedLineHandler locked_gcs_;
  std::unique_ptr<host::Dashboard> dashboard_;
  std::unique_ptr<ServeCamera> camera_;  // the dashboard's panel: destroyed before it
  std::unique_ptr<host::HttpServer> http_;
  std::unique_ptr<host::LineServer> server_;
  std::thread line_thread_, http_thread_;
  std::exception_ptr line_error_, http_error_, camera_error_;
};

void print_serve_summary(const ServeOptions& o, Network& net, const std::string& daq_name,
                         const runtime::ControlLoop& loop, const runtime::LoopResult& r,
                         const runtime::SafetyLimits& safety, const runtime::RealtimeReport& rt,
                         const std::vector<std::string>& fault_loads) {
  const host::GcsStats& gs = net.gcs().stats();
  const host::LineServerStats ns = net.server().stats();
  const runtime::LoopStats& st = loop.stats();
  const std::string stop_reason = procedures::stop_reason_text(r);
  if (!o.json) {
    fmt::print(
        "serve: {} ticks, stopped by {}; {} clients ({} refused), {} lines, {} GCS errors, {} "
        "faults, {} samples dropped, {} overruns\n",
        r.ticks, stop_reason, ns.accepted, ns.refused_max_clients, gs.lines, gs.errors, gs.faults,
        r.host_samples_dropped, st.overruns);
    fmt::print("{}", faults_text(r.faults, fault_loads));
    return;
  }
  nlohmann::json j;
  j["daq"] = daq_name;
  j["rate_Hz"] = o.rate_Hz;
  j["ticks"] = r.ticks;
  j["stop_reason"] = stop_reason;
  j["overruns"] = st.overruns;
  const auto us = [](std::int64_t t_ns) { return static_cast<double>(t_ns) * 1e-3; };
  j["period_error_p50_us"] = us(st.period_error.percentile_ns(0.5));
  j["period_error_p99_us"] = us(st.period_error.percentile_ns(0.99));
  j["period_error_max_us"] = us(st.period_error.max_ns());
  j["wake_latency_p50_us"] = us(st.wake_latency.percentile_ns(0.5));
  j["wake_latency_p99_us"] = us(st.wake_latency.percentile_ns(0.99));
  j["wake_latency_max_us"] = us(st.wake_latency.max_ns());
  j["realtime"] = {{"sched_fifo", rt.fifo}, {"mlockall", rt.memory_locked}};
  j["faults"] = gs.faults;
  j["faults_latched"] = faults_json(r.faults, fault_loads);
  j["faults_latched_count"] = r.faults.count;
  j["clients_accepted"] = ns.accepted;
  j["clients_refused"] = ns.refused_max_clients;
  j["clients_dropped_slow"] = ns.disconnected_slow;
  j["clients_dropped_idle"] = ns.disconnected_idle;
  j["clients_evicted_for_room"] = ns.evicted_for_room;
  j["clients_refused_http"] = ns.refused_http;  // an HTTP request at the GCS port
  j["clients_failed"] = ns.failed;              // a line whose handling threw
  j["command_lines"] = gs.lines;
  j["gcs_errors"] = gs.errors;
  j["loop_commands_applied"] = r.host_commands_applied;
  j["samples_dropped"] = r.host_samples_dropped;
  j["max_output_slew_V_per_ms"] = r.max_output_slew_V_per_ms;
  j["safety"] = procedures::safety_json(safety);
  if (const host::HttpServer* http = net.http()) {
    const host::HttpServerStats hs = http->stats();
    j["http"] = {{"requests", hs.requests},
                 {"refused", hs.refused},
                 {"unauthorised", hs.unauthorised},
                 {"streams_opened", hs.streams_opened},
                 {"dropped_slow", hs.dropped_slow},
                 {"events_sent", net.dashboard()->events_sent()},
                 {"refused_streams", hs.refused_streams},
                 {"evicted_for_room", hs.evicted_for_room}};
  }
  fmt::print("{}\n", j.dump(2));
}

int serve(const ServeOptions& o) {
  check_serve_options(o);
  const std::string token = http_token(o);
  // With a camera the file may hold [camera] too (one file serves `measure` and `serve`).
  camera::InstrumentConfig instrument;
  if (!o.config.empty() && !o.camera.empty())
    instrument = camera::load_instrument_config(o.config);
  else if (!o.config.empty())
    instrument.installation = runtime::load_installation_config(o.config);
  const runtime::InstallationConfig& installation = instrument.installation;
  const config::ProjectConfig& config = installation.project;
  const runtime::SafetyLimits limits =
      procedures::loop_safety_limits(installation.safety, o.max_overruns);
  // The stack first: a bad --fault, --daq or device is named before the twin's calibration runs.
  procedures::LoopStack stack(stack_options(o), config);
  const runtime::SafetyLimits safety =
      runtime::resolve_overrun_trip(limits, stack.sim() != nullptr);
  const procedures::LoopCalibration cal = procedures::resolve_calibration(
      o.calibration, o.daq, config, o.seed, 1.0 / o.rate_Hz, o.max_physics_steps);
  calibration::refuse_fringe_lock(cal, "serve");
  const host::StageModel model = procedures::loop_stage_model(
      config, cal, safety, o.calibration.empty() ? "built-in calibration" : o.calibration,
      o.config.empty() ? "the built-in configuration" : o.config);

  CameraSetup camera_setup;
  if (!o.camera.empty())
    camera_setup = open_camera(o, instrument.camera, cal);
  const std::string camera_line =
      camera_setup.camera
          ? fmt::format("piezoshift serve: camera {} ({} x {} px) on the dashboard\n",
                        camera_setup.camera->name(), camera_setup.camera->settings().width_px,
                        camera_setup.camera->settings().height_px)
          : std::string();

  runtime::HostLink link;
  const std::string daq_name = stack.daq().name();
  Network net(o, model, link, static_cast<double>(stack.period_ns()) * 1e-9, daq_name, token,
              std::move(camera_setup));
  runtime::LoopConfig lc;
  lc.rate_Hz = o.rate_Hz;
  lc.duration_s = o.duration_s;
  lc.stop_signal = &procedures::g_stop_signal;
  lc.stop_when_safe_after_fault = false;  // a client clears faults (SVO)
  lc.host = &link;
  runtime::LoopStatus status;  // the faults' source for the reporter
  lc.status = &status;
  runtime::ControlLoop loop(lc, cal.params, safety, stack.daq(), stack.clock(),
                            runtime::SetpointProfile::step(0.0), stack.telemetry());

  procedures::StopSignals signals;
  stack.start_logging();
  net.start();  // before the real-time request: the network threads stay normal threads
  FaultReporter fault_reporter(status);  // likewise; each fault on stderr as it latches
  if (const host::HttpServer* http = net.http())
    fmt::print("piezoshift serve: dashboard on http://{}:{}/{}\n", o.http_bind, http->port(),
               token.empty() ? "" : " (token required)");
  fmt::print("piezoshift serve: GCS 2.0 on {}:{}, loop at {:g} Hz on {}\n", o.bind,
             net.server().port(), o.rate_Hz, daq_name);
  fmt::print("{}", camera_line);
  fmt::print("piezoshift serve: safety ({}): {}\n",
             o.config.empty() ? "built in" : o.config + " [safety]", runtime::describe(safety));
  std::fflush(stdout);
  const runtime::RealtimeReport rt = procedures::request_realtime_or_warn(o.cpu);
  // Even under SCHED_FIFO (which preempts them) they cost the loop overruns there: with them on
  // its CPU, scripts/serve-latency counted 13 and 17 overruns under attack against 9 idle.
  // The fault reporter too: it reads /proc/loadavg and prints when a fault latches.
  if (rt.cpu >= 0 && !(net.keep_off_cpu(rt.cpu) && fault_reporter.keep_off_cpu(rt.cpu)))
    fmt::print(stderr,
               "piezoshift serve: warning: the network and fault-report threads share CPU {} "
               "with the loop (no other CPU, or refused)\n",
               rt.cpu);
  if (host::Dashboard* dashboard = net.dashboard())
    dashboard->set_realtime({true, rt.fifo, rt.memory_locked, rt.cpu});

  stack.daq().activate();
  g_loop_ramped.store(false);
  const std::terminate_handler previous = std::set_terminate(ramp_then_abort);
  const runtime::LoopResult r = loop.run();
  g_loop_ramped.store(true);
  stack.daq().deactivate();
  fault_reporter.stop();
  net.stop();
  stack.stop_logging();
  std::set_terminate(previous);  // every thread joined
  net.rethrow_failure();
  print_serve_summary(o, net, daq_name, loop, r, safety, rt, fault_reporter.loads());
  fmt::print("{}", device_error_line(stack.daq()));
  return report_unsafe_outputs(stack.daq(), "piezoshift serve") ? kExitFault : 0;
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
  add_physics_budget_option(cmd, o->max_physics_steps);
  cmd->add_option("--seed", o->seed, "twin noise seed")
      ->capture_default_str()
      ->check(whole_number(0, kAnyUnsigned));
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
  cmd->add_option("--idn", o->idn, "*IDN?'s answer (default: piezoshift's, naming E-727)");
  cmd->add_option("--settle-s", o->settle_s, "ONT? needs the tolerance held this long (s)")
      ->capture_default_str();
  cmd->add_option("--max-overruns", o->max_overruns,
                  "consecutive deadline overruns that trip the supervisor (default: [safety] "
                  "max_consecutive_overruns, 3)")
      ->check(whole_number(1, runtime::kMaxConsecutiveOverruns));
  cmd->add_option("--cpu", o->cpu, "CPU to pin the loop to (-1: the last one, -2: none)")
      ->capture_default_str();
  cmd->add_option("--log", o->log, "CSV log of every tick (flushed every 0.25 s)");
  cmd->add_option("--fault", o->faults,
                  "inject a fault into the twin: KIND@T_S[:CHANNEL], repeatable (docs/safety.md)");
  cmd->add_option("--http-port", o->http_port,
                  "serve the live dashboard on this port (0: any free port; docs/dashboard.md)");
  cmd->add_option("--http-bind", o->http_bind,
                  "IPv4 address of the dashboard; outside loopback only with a token")
      ->capture_default_str();
  cmd->add_option("--http-token", o->http_token,
                  "access token every dashboard request must carry (>= 16 characters)");
  cmd->add_option("--http-token-file", o->http_token_file,
                  "file whose first line is the access token");
  cmd->add_option("--http-max-clients", o->http_max_clients, "dashboard connections at once")
      ->capture_default_str();
  cmd->add_option("--camera", o->camera,
                  "twin, files:DIR or aravis:ID: the dashboard's live view and measurements "
                  "(docs/dashboard.md; [camera] of --config)");
  cmd->add_option("--surface", o->surface,
                  "the twin camera's test surface, as `psi simulate` takes it (Z4=40,rough=0.5)");
  cmd->add_option("--mask", o->mask, "the pupil as a PNG (cameras other than the twin)");
  cmd->add_flag("--json", o->json, "print the summary at exit as JSON");
  cmd->callback([&action, o] { action = [o] { return serve(*o); }; });
}

}  // namespace piezoshift::app
