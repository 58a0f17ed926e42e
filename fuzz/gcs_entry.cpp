// The GCS target: host::GcsInterpreter on the twin's stage model, fed the input's lines as
// LineServer frames them, with a stand-in for the real-time loop on its own thread.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>

#include "entry_points.hpp"
#include "piezoshift/host/gcs_interpreter.hpp"
#include "piezoshift/host/http_line.hpp"
#include "piezoshift/plant/geometry.hpp"
#include "piezoshift/runtime/safety_supervisor.hpp"

namespace piezoshift::fuzz {
namespace {

using runtime::HostCommand;

// Applies every command at once and sends one sample per 0.1 ms "tick" (the interpreter waits
// for the loop in places, e.g. two WGO in a row), reading each wave table it is handed in full so
// that AddressSanitizer sees a table the interpreter freed or overwrote too early.
class StandInLoop {
 public:
  explicit StandInLoop(runtime::HostLink& link) : link_(link), thread_([this] { run(); }) {}
  ~StandInLoop() {
    stop_.store(true);
    thread_.join();
  }

 private:
  void run() {
    runtime::HostSample s{};
    s.state = static_cast<std::uint8_t>(runtime::SupervisorState::kRunning);
    double sink = 0.0;
    while (!stop_.load()) {
      for (HostCommand c{}; link_.commands.try_pop(c);) {
        s.applied_sequence = c.sequence;
        switch (c.kind) {
          case HostCommand::Kind::kServoOn:
            s.closed_loop = 1;
            s.zd_um = c.zd_um;
            break;
          case HostCommand::Kind::kMoveTo:
            s.zd_um = c.zd_um;
            break;
          case HostCommand::Kind::kServoOff:
            s.closed_loop = 0;
            s.wave_running = 0;
            break;
          case HostCommand::Kind::kOpenLoop:
            s.ao_V = c.ao_V;
            break;
          case HostCommand::Kind::kActuators:  // the guided calibration's, never the server's
            break;
          case HostCommand::Kind::kConfigure: {  // SPA's set, taken as the loop takes it
            control::SemiClosedLoopParams p{};
            (void)link_.params.try_pop(p);
            break;
          }
          case HostCommand::Kind::kWave: {
            const auto bit = static_cast<std::uint8_t>(1u << c.wave.generator);
            if (c.wave.action == runtime::WaveCommand::Action::kStart) {
              for (std::uint32_t i = 0; i < c.wave.length; ++i)
                sink += c.wave.values[i];
              s.wave_running |= bit;
            } else {
              s.wave_running &= static_cast<std::uint8_t>(~bit);
            }
            break;
          }
        }
      }
      s.t_s = static_cast<double>(s.tick) * 1e-3;
      link_.samples.try_push(s);
      ++s.tick;
      std::this_thread::sleep_for(std::chrono::microseconds(100));
    }
    sink_ = sink;
  }

  runtime::HostLink& link_;
  std::atomic<bool> stop_{false};
  double sink_ = 0.0;
  std::thread thread_;  // last: starts once the members above exist
};

// An answer's size is bounded before it is made, whatever the arguments (a DRR? of every
// table, HLP?, the 64 items a query may name, values of 300 digits): all its parts together at
// most GcsInterpreter::kMaxAnswerBytes, each part at most kMaxPartBytes beyond what the line
// itself holds (SPA? echoes its items). The rest of a pending answer is taken as LineServer does.
void check_answer(host::GcsInterpreter& gcs, host::ClientId client, std::string_view line,
                  std::string answer) {
  using host::GcsInterpreter;
  std::size_t whole = 0;
  for (;;) {
    if (answer.size() > GcsInterpreter::kMaxPartBytes + line.size())
      throw std::logic_error("gcs: a part of " + std::to_string(answer.size()) +
                             " bytes answers the line " + std::string(line.substr(0, 80)));
    whole += answer.size();
    if (!gcs.answer_pending(client))
      break;
    answer = gcs.more_answer(client);
  }
  if (whole > GcsInterpreter::kMaxAnswerBytes)
    throw std::logic_error("gcs: an answer of " + std::to_string(whole) + " bytes to the line " +
                           std::string(line.substr(0, 80)));
}

}  // namespace

void gcs_input(std::string_view data) {
  static const host::StageModel model(host::stage_model_params(plant::GeometryParams{}));
  constexpr std::size_t kMaxLineBytes = host::LineServerLimits{}.max_line_bytes;
  runtime::HostLink link;
  host::GcsInterpreter gcs(model, link, 1e-3, host::GcsOptions{});
  const StandInLoop loop(link);
  constexpr host::ClientId kClient = 1;
  gcs.on_connect(kClient);
  gcs.on_connect(kClient + 1);  // a second session, for the answers that go to every client
  // LineServer's framing: a single-character command where a line starts, otherwise lines at LF
  // without one trailing CR; the last line without LF is dropped, as at EOF. A first line that is
  // HTTP's closes the connection before anything runs.
  bool first_line = true;
  while (!data.empty()) {
    if (gcs.is_immediate(data.front())) {
      gcs.on_immediate(kClient, data.front());
      data.remove_prefix(1);
      continue;
    }
    const std::size_t lf = data.find('\n');
    if (lf == std::string_view::npos)
      break;
    std::string_view line = data.substr(0, lf);
    if (!line.empty() && line.back() == '\r')
      line.remove_suffix(1);
    if (std::exchange(first_line, false) && host::looks_like_http(line))
      break;
    if (line.size() > kMaxLineBytes)
      gcs.on_overlong_line(kClient);
    else
      check_answer(gcs, kClient, line, gcs.on_line(kClient, line));
    gcs.on_poll();
    data.remove_prefix(lf + 1);
  }
  gcs.on_disconnect(kClient);
  gcs.on_disconnect(kClient + 1);
}

}  // namespace piezoshift::fuzz
