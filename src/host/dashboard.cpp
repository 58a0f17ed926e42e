#include "piezoshift/host/dashboard.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "piezoshift/host/gcs_client.hpp"
#include "piezoshift/host/line_server.hpp"
#include "piezoshift/runtime/safety_supervisor.hpp"

namespace piezoshift::host {

namespace {

//! ~40 s of samples at 1 kHz between two updates (~7 MB): an HTTP thread stalled longer loses the
//! oldest.
constexpr std::size_t kMaxPendingRows = 4096 * 10;

std::uint64_t now_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::steady_clock::now().time_since_epoch())
                                        .count());
}

// What each latched reason means for the operator (docs/safety.md has the rules).
const char* fault_sentence(runtime::FaultReason reason) {
  using R = runtime::FaultReason;
  switch (reason) {
    case R::kNone:
      return "";
    case R::kSgsNotFinite:
      return "a strain-gauge reading is not a number (failed conversion)";
    case R::kSgsRail:
      return "a strain-gauge reading is stuck at the ADC rail (open bridge or broken wire)";
    case R::kSgsRange:
      return "a strain-gauge reading is outside the conditioner's 0..10 V";
    case R::kSgsJump:
      return "a strain-gauge reading jumped faster than the stage can move";
    case R::kTracking:
      return "the stage does not follow its target (|S - y| > 1 um for 0.1 s)";
    case R::kResponse:
      return "a stack does not answer its drive (amplifier, stack or sensor failure)";
    case R::kSaturation:
      return "an output is pinned at 10 V: the target is out of reach";
    case R::kOverruns:
      return "the loop missed its deadline too many times in a row";
    case R::kDaqRead:
      return "the DAQ read failed";
    case R::kDaqWrite:
      return "the DAQ write failed";
    case R::kOutputNotFinite:
      return "the controller's output is not a number";
    case R::kOscillation:
      return "the loop oscillates: its tracking error keeps reversing with the target steady";
  }
  return "unknown";
}

// JSON number, or null for NaN and infinities (JSON has neither).
void append_number(std::string& out, double v, int digits) {
  if (std::isfinite(v))
    fmt::format_to(std::back_inserter(out), "{:.{}g}", v, digits);
  else
    out += "null";
}

// "key=value" lines of a GCS answer -> the values in order (NaN when unparsable).
std::vector<double> values_of(const std::vector<std::string>& lines) {
  std::vector<double> out;
  for (const std::string& l : lines) {
    const std::size_t eq = l.find('=');
    try {
      out.push_back(eq == std::string::npos ? std::nan("") : std::stod(l.substr(eq + 1)));
    } catch (const std::exception&) {
      out.push_back(std::nan(""));
    }
  }
  return out;
}

double percentile(std::vector<double>& v, double q) {
  if (v.empty())
    return std::nan("");
  const auto k = static_cast<std::size_t>(std::round(q * static_cast<double>(v.size() - 1)));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

}  // namespace

Dashboard::Dashboard(GcsInterpreter& gcs, std::mutex& gcs_mutex, std::string_view page,
                     const DashboardOptions& options)
    : gcs_(gcs), mutex_(gcs_mutex), page_(page), options_(options) {
  stride_ = static_cast<std::size_t>(
      std::max(1.0, std::ceil(options.loop_rate_Hz / options.max_stream_rate_Hz - 1e-9)));
  const std::lock_guard lock(mutex_);
  gcs_.on_connect(kSession);
}

Dashboard::~Dashboard() {
  const std::lock_guard lock(mutex_);
  gcs_.on_disconnect(kSession);
}

void Dashboard::set_realtime(const DashboardRealtime& rt) noexcept {
  realtime_cpu_.store(rt.cpu);
  realtime_.store((rt.known ? 1 : 0) | (rt.sched_fifo ? 2 : 0) | (rt.mlockall ? 4 : 0));
}

void Dashboard::on_sample(const runtime::HostSample& s, const RecorderInput& d) {
  if (pending_.size() >= kMaxPendingRows) {
    // The HTTP thread has stalled for ~40 s: drop the older half at once (amortised O(1)).
    const std::size_t half = pending_.size() / 2;
    pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(half));
    pending_dropped_ += half;
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const StageModel& model = gcs_.model();
  Row r;
  r.tick = s.tick;
  r.t_s = s.t_s;
  r.setpoint = s.closed_loop != 0 ? model.pose_from_points(s.zd_um) : AxisValues{nan, nan, nan};
  r.position = d.position;
  r.sgs_V = s.sgs_V;
  r.amplifier_V = d.channel_V;
  r.interferometer = d.interferometer;
  r.truth = s.has_truth != 0 ? model.pose_from_points(s.truth_um) : AxisValues{nan, nan, nan};
  r.wake_latency_us = s.wake_latency_us;
  r.overrun = s.overrun;
  r.state = s.state;
  r.fault_reason = s.fault_reason;
  r.fault_channel = s.fault_channel;
  pending_.push_back(r);
  if (panel_ != nullptr)
    panel_->on_sample(s, d);
}

bool Dashboard::is_panel_path(std::string_view path) noexcept {
  for (const std::string_view root :
       {std::string_view("/api/camera"), std::string_view("/api/measure")})
    if (path.starts_with(root) && (path.size() == root.size() || path[root.size()] == '/'))
      return true;
  return false;
}

std::vector<std::string> Dashboard::query(std::string_view line) {
  return GcsClient::split_answer(gcs_.on_line(kSession, line));
}

void Dashboard::on_poll(HttpServer& server) {
  const std::uint64_t now = now_ns();
  if (now < next_update_ns_)
    return;
  // A fixed schedule (not now + period), so the rate holds whatever the poll granularity.
  const auto period_ns = static_cast<std::uint64_t>(options_.update_period_s * 1e9);
  next_update_ns_ =
      next_update_ns_ + period_ns > now ? next_update_ns_ + period_ns : now + period_ns;
  batch_.clear();
  std::vector<std::string> servo, on_target, target, position;
  {
    const std::lock_guard lock(mutex_);
    gcs_.drain();
    std::swap(batch_, pending_);
    samples_dropped_ += pending_dropped_;
    pending_dropped_ = 0;
    servo = query("SVO?");
    on_target = query("ONT?");
    target = query("MOV?");
    position = query("POS?");
  }
  // Timing and fault bookkeeping, outside the lock.
  const auto window = static_cast<std::size_t>(options_.timing_window_s * options_.loop_rate_Hz);
  for (const Row& r : batch_) {
    if (have_tick_ && r.tick > last_tick_ + 1)
      samples_dropped_ += r.tick - last_tick_ - 1;
    // |(W_k - W_k-1) - T| = |latency_k - latency_k-1| between consecutive ticks on consecutive
    // deadlines (after an overrun the loop skips slots: not a period of the schedule).
    if (have_tick_ && r.tick == last_tick_ + 1 && last_.overrun == 0)
      period_errors_us_.push_back(std::fabs(r.wake_latency_us - last_.wake_latency_us));
    last_tick_ = r.tick;
    have_tick_ = true;
    overruns_ += r.overrun;
    latencies_us_.push_back(r.wake_latency_us);
    if (r.fault_reason != 0) {
      if (r.fault_reason != last_fault_reason_ || last_.fault_reason == 0)
        last_fault_t_s_ = r.t_s;
      last_fault_reason_ = r.fault_reason;
      last_fault_channel_ = r.fault_channel;
    }
    last_ = r;
  }
  remember(batch_);
  while (latencies_us_.size() > window)
    latencies_us_.pop_front();
  while (period_errors_us_.size() > window)
    period_errors_us_.pop_front();

  nlohmann::json st;
  st["t_s"] = last_.t_s;
  st["daq"] = options_.daq_name;
  st["camera"] = panel_ != nullptr;
  st["loop_rate_Hz"] = options_.loop_rate_Hz;
  st["stream_rate_Hz"] = options_.loop_rate_Hz / static_cast<double>(stride_);
  const auto number = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nullptr; };
  st["servo_on"] = !servo.empty() && servo.front() == "Z=1";
  const std::vector<double> ont = values_of(on_target);
  const std::vector<double> mov = values_of(target);
  const std::vector<double> pos = values_of(position);
  const char* keys[3] = {"z_um", "u_urad", "v_urad"};
  for (std::size_t a = 0; a < 3; ++a) {
    st["on_target"][keys[a]] = a < ont.size() && ont[a] == 1.0;
    st["target"][keys[a]] = number(a < mov.size() ? mov[a] : std::nan(""));
    st["position"][keys[a]] = number(a < pos.size() ? pos[a] : std::nan(""));
  }
  const auto state = static_cast<runtime::SupervisorState>(last_.state);
  st["supervisor"] = runtime::to_string(state);
  const bool faulted = state == runtime::SupervisorState::kFaulted;
  const auto fault_json = [&](std::uint8_t reason, std::int8_t channel, double t_s) {
    const auto r = static_cast<runtime::FaultReason>(reason);
    return nlohmann::json{{"reason", runtime::to_string(r)},
                          {"text", fault_sentence(r)},
                          {"channel", channel >= 0 ? nlohmann::json(channel + 1) : nullptr},
                          {"t_s", t_s}};
  };
  st["fault"] = faulted && last_.fault_reason != 0
                    ? fault_json(last_.fault_reason, last_.fault_channel, last_fault_t_s_)
                    : nullptr;
  st["last_fault"] = last_fault_reason_ != 0
                         ? fault_json(last_fault_reason_, last_fault_channel_, last_fault_t_s_)
                         : nullptr;
  std::vector<double> lat(latencies_us_.begin(), latencies_us_.end());
  std::vector<double> per(period_errors_us_.begin(), period_errors_us_.end());
  st["timing"] = {{"window_s", static_cast<double>(lat.size()) / options_.loop_rate_Hz},
                  {"period_error_p50_us", number(percentile(per, 0.50))},
                  {"period_error_p99_us", number(percentile(per, 0.99))},
                  {"period_error_max_us", number(percentile(per, 1.0))},
                  {"wake_latency_p50_us", number(percentile(lat, 0.50))},
                  {"wake_latency_p99_us", number(percentile(lat, 0.99))},
                  {"wake_latency_max_us", number(percentile(lat, 1.0))},
                  {"overruns", overruns_},
                  {"samples_dropped", samples_dropped_}};
  const int rt = realtime_.load();
  st["realtime"] = (rt & 1) != 0 ? nlohmann::json{{"sched_fifo", (rt & 2) != 0},
                                                  {"mlockall", (rt & 4) != 0},
                                                  {"cpu", realtime_cpu_.load()}}
                                 : nullptr;
  st["streams"] = server.stream_count();
  last_status_ = st.dump();

  if (server.stream_count() == 0)
    return;
  std::string event = "event: update\ndata: {\"status\":";
  event += last_status_;
  event += ",\"samples\":";
  event += samples_json(batch_);
  event += "}\n\n";
  server.broadcast(event);
  events_sent_.fetch_add(1);
}

void Dashboard::remember(const std::vector<Row>& rows) {
  for (const Row& r : rows)
    if (r.tick % stride_ == 0)
      history_.push_back(r);
  while (!history_.empty() && history_.front().t_s < history_.back().t_s - options_.history_s)
    history_.pop_front();
}

HttpResponse Dashboard::history(const HttpRequest& request) const {
  double seconds = 2.0;
  if (const auto it = request.query.find("seconds"); it != request.query.end()) {
    char* end = nullptr;
    seconds = std::strtod(it->second.c_str(), &end);
    if (it->second.empty() || *end != '\0' || !(seconds > 0.0 && seconds <= options_.history_s))
      return HttpResponse::text(
          400, fmt::format("seconds: a number above 0 and at most {:g}", options_.history_s));
  }
  std::vector<Row> rows;
  if (!history_.empty()) {
    const double from = history_.back().t_s - seconds;
    const auto first = std::lower_bound(history_.begin(), history_.end(), from,
                                        [](const Row& r, double t) { return r.t_s < t; });
    const auto n = static_cast<std::size_t>(history_.end() - first);
    // Every k-th row counted from the newest, so that the answer ends where the stream goes on.
    const std::size_t k =
        std::max<std::size_t>(1, (n + options_.max_history_rows - 1) /
                                     std::max<std::size_t>(1, options_.max_history_rows));
    for (std::size_t i = (n - 1) % k; i < n; i += k)
      rows.push_back(*(first + static_cast<std::ptrdiff_t>(i)));
    return HttpResponse::json(
        200, fmt::format("{{\"every\":{},\"samples\":{}}}", k, samples_json(rows)));
  }
  return HttpResponse::json(200, "{\"every\":1,\"samples\":{}}");
}

std::string Dashboard::samples_json(const std::vector<Row>& rows) const {
  // Columns: cheap to append to the page's chart arrays, and half the bytes of row objects.
  std::vector<const Row*> picked;
  for (const Row& r : rows)
    if (r.tick % stride_ == 0)
      picked.push_back(&r);
  std::string out = "{";
  const auto column = [&](const char* name, auto get, int digits) {
    if (out.size() > 1)
      out += ',';
    fmt::format_to(std::back_inserter(out), "\"{}\":[", name);
    for (std::size_t i = 0; i < picked.size(); ++i) {
      if (i > 0)
        out += ',';
      append_number(out, get(*picked[i]), digits);
    }
    out += ']';
  };
  column(
      "t_s", [](const Row& r) { return r.t_s; }, 10);
  const char* pose_names[3][4] = {
      {"setpoint_z_um", "position_z_um", "interferometer_z_um", "true_z_um"},
      {"setpoint_u_urad", "position_u_urad", "interferometer_u_urad", "true_u_urad"},
      {"setpoint_v_urad", "position_v_urad", "interferometer_v_urad", "true_v_urad"}};
  for (std::size_t a = 0; a < 3; ++a) {
    column(
        pose_names[a][0], [a](const Row& r) { return r.setpoint[a]; }, 7);
    column(
        pose_names[a][1], [a](const Row& r) { return r.position[a]; }, 7);
    column(
        pose_names[a][2], [a](const Row& r) { return r.interferometer[a]; }, 7);
    column(
        pose_names[a][3], [a](const Row& r) { return r.truth[a]; }, 7);
  }
  const char* sgs_names[3] = {"sgs1_V", "sgs2_V", "sgs3_V"};
  const char* amp_names[3] = {"amp1_V", "amp2_V", "amp3_V"};
  for (std::size_t i = 0; i < 3; ++i)
    column(
        sgs_names[i], [i](const Row& r) { return r.sgs_V[i]; }, 6);
  for (std::size_t i = 0; i < 3; ++i)
    column(
        amp_names[i], [i](const Row& r) { return r.amplifier_V[i]; }, 5);
  out += '}';
  return out;
}

HttpResponse Dashboard::on_request(const HttpRequest& request) {
  if (request.path == "/" || request.path == "/index.html") {
    if (request.method != "GET")
      return HttpResponse::text(405, "GET only");
    HttpResponse r;
    r.content_type = "text/html; charset=utf-8";
    r.body = page_;
    return r;
  }
  if (request.path == "/api/stream") {
    if (request.method != "GET")
      return HttpResponse::text(405, "GET only");
    HttpResponse r;
    r.stream = true;
    // retry: how long EventSource waits before reconnecting; the first status at once.
    r.body = "retry: 1000\n\n";
    if (!last_status_.empty())
      r.body += "event: update\ndata: {\"status\":" + last_status_ + ",\"samples\":{}}\n\n";
    return r;
  }
  if (request.path == "/api/history") {
    if (request.method != "GET")
      return HttpResponse::text(405, "GET only");
    return history(request);
  }
  if (request.path == "/api/status") {
    if (request.method != "GET")
      return HttpResponse::text(405, "GET only");
    return HttpResponse::json(200, last_status_.empty() ? "{}" : last_status_);
  }
  if (request.path == "/api/command") {
    if (request.method != "POST")
      return HttpResponse::text(405, "POST only");
    return command(request);
  }
  if (is_panel_path(request.path)) {
    if (panel_ != nullptr)
      return panel_->on_request(request);
    return HttpResponse::text(
        404, fmt::format("{}: serve runs without a camera; start it with --camera twin, "
                         "files:DIR or aravis:ID for the live view and measurements",
                         request.path));
  }
  return HttpResponse::text(404, fmt::format("no such page: {}", request.path));
}

HttpResponse Dashboard::command(const HttpRequest& request) {
  nlohmann::json body;
  try {
    body = nlohmann::json::parse(request.body);
  } catch (const nlohmann::json::exception& e) {
    return HttpResponse::text(400, fmt::format("body is not JSON: {}", e.what()));
  }
  if (!body.is_object() || !body.contains("commands") || !body["commands"].is_array())
    return HttpResponse::text(400, "expected {\"commands\": [\"GCS line\", ...]}");
  const nlohmann::json& list = body["commands"];
  if (list.empty() || list.size() > options_.max_commands)
    return HttpResponse::text(
        400, fmt::format("commands: 1 to {} GCS lines per request", options_.max_commands));
  Job job;
  for (const nlohmann::json& item : list) {
    if (!item.is_string())
      return HttpResponse::text(400, "commands: every item must be a string");
    const std::string& line = item.get_ref<const std::string&>();
    if (line.empty() || line.size() > options_.max_command_bytes)
      return HttpResponse::text(
          400, fmt::format("a GCS line must be 1 to {} bytes", options_.max_command_bytes));
    for (const char c : line)
      if (static_cast<unsigned char>(c) < 0x20 && c != '\t')
        return HttpResponse::text(400, "a GCS line must not hold control characters");
    job.lines.push_back(line);
  }
  jobs_[request.client] = std::move(job);
  return HttpResponse::deferred();  // run a turn at a time: resume()
}

void Dashboard::run_turn(Job& job) {
  const auto turn_end = std::chrono::steady_clock::now() +
                        std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                            std::chrono::duration<double>(std::min(options_.turn_budget_s, 1e6)));
  std::size_t handled = 0;
  std::size_t turn_bytes = 0;
  const LineServerLimits line_limits;
  const std::lock_guard lock(mutex_);
  if (!job.started) {
    // Errors queued before this request (a fault's -1024) are not this request's.
    for (int i = 0; i < 32 && gcs_.on_line(kSession, "ERR?") != "0\n"; ++i) {
    }
    job.started = true;
  }
  // A GCS client's turn (line_server.hpp): lines (or parts of a long answer), answer bytes and
  // time, whichever ends first; the line that crosses is finished.
  while (!job.done && (job.in_answer || job.next < job.lines.size()) &&
         (handled == 0 || (handled < LineServer::kLinesPerTurn &&
                           turn_bytes < line_limits.output_high_water_bytes &&
                           std::chrono::steady_clock::now() < turn_end))) {
    ++handled;
    const std::string part =
        job.in_answer ? gcs_.more_answer(kSession) : gcs_.on_line(kSession, job.lines[job.next++]);
    turn_bytes += part.size();
    job.answer_bytes += part.size();
    if (job.answer_bytes > options_.max_answer_bytes) {
      job.done = true;
      job.failed_line = job.lines[job.next - 1];
      gcs_.on_line(kSession, "");  // drops the rest of the answer
      break;
    }
    job.partial += part;
    job.in_answer = gcs_.answer_pending(kSession);
    if (job.in_answer)
      continue;
    const int code = std::stoi(gcs_.on_line(kSession, "ERR?"));
    job.answers.push_back(std::move(job.partial));
    job.partial.clear();
    if (code != 0) {
      job.done = true;
      job.code = code;
      job.failed_line = job.lines[job.next - 1];
    }
  }
  job.done = job.done || (!job.in_answer && job.next == job.lines.size());
}

HttpResponse Dashboard::job_response(const Job& job) const {
  nlohmann::json result;
  result["answers"] = job.answers;
  result["ok"] = job.failed_line.empty();
  int status = 200;
  if (job.code != 0) {
    // A refused GCS command: 422 with its GCS error number and text, so that curl -f fails too.
    status = 422;
    result["error"] = {{"code", job.code},
                       {"text", describe(static_cast<GcsError>(job.code))},
                       {"command", job.failed_line}};
  } else if (!job.failed_line.empty()) {
    status = 413;
    result["error"] = {
        {"text", fmt::format("the answers of one request exceed {} bytes: ask for less (e.g. "
                             "DRR? in parts); the lines before this one were applied",
                             options_.max_answer_bytes)},
        {"command", job.failed_line}};
  }
  return HttpResponse::json(status, result.dump());
}

HttpResponse Dashboard::resume(std::uint64_t client) {
  const auto it = jobs_.find(client);
  if (it == jobs_.end())
    return HttpResponse::text(500, "no command list for this connection");
  if (running_job_ != 0 && running_job_ != client)
    return HttpResponse::deferred();  // another POST's lines run first
  running_job_ = client;
  Job& job = it->second;
  run_turn(job);
  if (!job.done)
    return HttpResponse::deferred();
  HttpResponse response = job_response(job);
  jobs_.erase(it);
  running_job_ = 0;
  return response;
}

void Dashboard::abandon(std::uint64_t client) {
  const auto it = jobs_.find(client);
  if (it == jobs_.end())
    return;
  if (it->second.in_answer) {
    const std::lock_guard lock(mutex_);
    gcs_.on_line(kSession, "");  // drops the rest of the answer
  }
  jobs_.erase(it);
  if (running_job_ == client)
    running_job_ = 0;
}

}  // namespace piezoshift::host
