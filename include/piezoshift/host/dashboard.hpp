#pragma once
// The live dashboard of `piezoshift serve --http-port` (docs/dashboard.md): the page, its event
// stream and its controls, served by an HttpServer on its own normal thread.
//
//   samples   the GCS interpreter hands every HostSample to on_sample() on the GCS thread (under
//             the shared mutex): the same stream its data recorder reads, so the web side adds
//             no path into the loop. They are kept in a bounded buffer (4 s of samples; beyond
//             that the oldest are dropped and counted) and, every update_period_s, turned into
//             one Server-Sent Event for all streams: columns of at most max_stream_rate_Hz
//             samples per second (every k-th sample, k = ceil(loop rate / max rate))
//   history   the stream's rows of the last history_s (60 s, the page's longest window) kept on
//             the HTTP thread, so that a page opened now draws its whole window at once: GET
//             /api/history?seconds=S answers the last S seconds in the stream's columns, thinned
//             to at most max_history_rows (every k-th row, the newest kept) so that 60 s stays
//             within a client's send queue. The GCS data recorder cannot serve this: its tables
//             hold what DRC chose, restart on every motion command and stop when full
//   status    with each update: servo, on target, target and position (the interpreter's own
//             SVO?, ONT?, MOV?, POS? on the dashboard's session), the supervisor's state and
//             latched fault with its reason, period-error and wake-latency percentiles over
//             the last timing_window_s (from the samples' wake latencies: period error
//             |(W_k - W_k-1) - T| = |latency_k - latency_k-1|, as runtime/period_stats.hpp),
//             overruns, and the real-time privileges granted
//   controls  POST /api/command {"commands": ["SVO Z 1 U 1 V 1", "MOV Z 5"]}: each line goes
//             through GcsInterpreter::on_line on the dashboard's own GCS session, then ERR?; the
//             first error stops the list and is answered with its GCS number and text. So every
//             limit and error of GCS applies unchanged. The lines run in turns, as a GCS
//             client's do (HttpResponse::deferred(), resume()): one turn holds the mutex for at
//             most LineServer::kLinesPerTurn lines, stops once its answers reach 16 KiB or it
//             has taken turn_budget_s (the line that crosses is finished), and the next turn is
//             the next round's, so a GCS client waits for at most one turn of a POST. The
//             answers of one POST are at most max_answer_bytes (beyond: 413, the lines before
//             it applied)
//   panel     with `serve --camera`, the camera's live view and the measurement
//             (dashboard_panel.hpp): the requests under /api/camera and /api/measure go to it,
//             and every sample; without one they are refused with 404 and why. The status says
//             whether there is one ("camera": true/false)
// The mutex is the one the GCS thread holds around the interpreter (LockedLineHandler); the HTTP
// thread holds it only to copy samples out and to run one turn of command lines, never across
// I/O.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "piezoshift/host/dashboard_panel.hpp"
#include "piezoshift/host/gcs_interpreter.hpp"
#include "piezoshift/host/http_server.hpp"
#include "piezoshift/host/sample_observer.hpp"

namespace piezoshift::host {

struct DashboardOptions {
  double loop_rate_Hz = 1000.0;
  double update_period_s = 0.04;       //!< 25 events per second
  double max_stream_rate_Hz = 1000.0;  //!< samples per second in the stream, at most
  double timing_window_s = 10.0;       //!< wake-latency percentiles over this span
  std::size_t max_commands = 32;       //!< per POST
  std::size_t max_command_bytes = 256;
  //! A POST's answers in all; a line whose answer crosses it ends the request with 413.
  std::size_t max_answer_bytes = std::size_t{2} << 20;
  //! One turn of a POST's lines stops once it has taken this long [s] (LineServerLimits').
  double turn_budget_s = 1e-3;
  std::string daq_name = "sim";
  double history_s = 60.0;              //!< rows kept for GET /api/history
  std::size_t max_history_rows = 8192;  //!< per answer (~1.6 MB of JSON)
};

//! What `serve` learnt at start-up, shown in the status (set from the loop's thread).
struct DashboardRealtime {
  bool known = false;
  bool sched_fifo = false;
  bool mlockall = false;
  int cpu = -1;
};

class Dashboard final : public HttpHandler, public SampleObserver {
 public:
  //! page: the HTML served at "/" (the embedded bundle). The dashboard opens a GCS session on gcs
  //! (under mutex); gcs must outlive it.
  Dashboard(GcsInterpreter& gcs, std::mutex& gcs_mutex, std::string_view page,
            const DashboardOptions& options);
  ~Dashboard() override;
  Dashboard(const Dashboard&) = delete;
  Dashboard& operator=(const Dashboard&) = delete;

  //! GCS thread, with gcs_mutex held (GcsInterpreter::drain through LockedLineHandler).
  void on_sample(const runtime::HostSample& sample, const RecorderInput& derived) override;

  //! HTTP thread.
  HttpResponse on_request(const HttpRequest& request) override;
  void on_poll(HttpServer& server) override;
  //! One turn of a POST's command lines.
  HttpResponse resume(std::uint64_t client) override;
  void abandon(std::uint64_t client) override;

  //! Before the servers start: the panel of /api/camera and /api/measure (null: none). It must
  //! outlive the dashboard's use of it.
  void set_panel(DashboardPanel* panel) noexcept { panel_ = panel; }
  //! The paths whose requests go to the panel: these and everything under them.
  static bool is_panel_path(std::string_view path) noexcept;

  //! Any thread.
  void set_realtime(const DashboardRealtime& rt) noexcept;
  std::uint64_t events_sent() const noexcept { return events_sent_.load(); }

  //! The GCS session of the dashboard; never a LineServer client id.
  static constexpr ClientId kSession = ~ClientId{0};

 private:
  //! One servo cycle as the dashboard shows it; NaN where there is nothing (no twin, open loop).
  struct Row {
    std::uint64_t tick = 0;
    double t_s = 0.0;
    AxisValues setpoint{};
    AxisValues position{};
    Vec3 sgs_V{};
    Vec3 amplifier_V{};
    AxisValues interferometer{};
    AxisValues truth{};
    double wake_latency_us = 0.0;
    std::uint8_t overrun = 0;
    std::uint8_t state = 0;
    std::uint8_t fault_reason = 0;
    std::int8_t fault_channel = -1;
  };

  //! A POST's lines, run a turn at a time (resume()).
  struct Job {
    std::vector<std::string> lines;
    std::size_t next = 0;  //!< the first line not run yet
    bool started = false;  //!< errors queued before the request have been taken
    std::size_t answer_bytes = 0;
    std::string partial;     //!< the answer of lines[next - 1] so far
    bool in_answer = false;  //!< its answer has parts to come (GcsInterpreter::answer_pending)
    std::vector<std::string> answers;
    bool done = false;
    int code = 0;             //!< the GCS error that stopped it (0: none)
    std::string failed_line;  //!< the line that stopped it (an error, or answers too large)
  };
  HttpResponse command(const HttpRequest& request);
  //! Runs lines of the job within one turn's budget, under the mutex.
  void run_turn(Job& job);
  //! The response of a finished job.
  HttpResponse job_response(const Job& job) const;
  std::string status_json();
  std::string samples_json(const std::vector<Row>& rows) const;
  //! Keeps the batch's stream rows in history_, dropping those older than history_s.
  void remember(const std::vector<Row>& rows);
  //! GET /api/history?seconds=S.
  HttpResponse history(const HttpRequest& request) const;
  //! Under the mutex: a query on the dashboard's session, its answer lines.
  std::vector<std::string> query(std::string_view line);

  GcsInterpreter& gcs_;
  std::mutex& mutex_;
  std::string page_;
  DashboardOptions options_;
  DashboardPanel* panel_ = nullptr;
  std::size_t stride_ = 1;

  // Filled by on_sample (under mutex_), emptied by on_poll.
  std::vector<Row> pending_;
  std::uint64_t pending_dropped_ = 0;

  // HTTP thread only: the POSTs being run, by HttpRequest::client.
  std::map<std::uint64_t, Job> jobs_;
  //! The job whose lines run (one at a time: they share the dashboard's session); 0: none.
  std::uint64_t running_job_ = 0;

  // HTTP thread only.
  std::uint64_t next_update_ns_ = 0;
  std::vector<Row> batch_;
  std::deque<Row> history_;  //!< the stream's rows (every stride_-th tick), oldest first
  std::deque<double> latencies_us_;
  std::deque<double> period_errors_us_;
  std::uint64_t overruns_ = 0;
  std::uint64_t samples_dropped_ = 0;
  std::uint64_t last_tick_ = 0;
  bool have_tick_ = false;
  Row last_{};
  std::uint8_t last_fault_reason_ = 0;
  std::int8_t last_fault_channel_ = -1;
  double last_fault_t_s_ = 0.0;
  std::string last_status_;

  std::atomic<int> realtime_{0};  // bit 0 known, 1 fifo, 2 mlockall; cpu separately
  std::atomic<int> realtime_cpu_{-1};
  std::atomic<std::uint64_t> events_sent_{0};
};

}  // namespace piezoshift::host
