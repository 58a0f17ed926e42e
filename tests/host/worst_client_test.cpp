// The servers' promise under attack: while one client sends the worst input it can within the
// limits, every other client's POS? is answered after at most two turns of the attacker's work,
// and no turn holds the interpreter (hence its mutex, which the dashboard shares) for more than a
// bounded amount of work. Counted in turns and bytes of answers made, never timed (the machine
// is shared); scripts/serve-latency measures the same in wall time against `piezoshift serve`.
//   GCS        an attacker that reads its answers (so it is never throttled) floods DRR? of the
//              largest size (8 tables x 8192 points, 1.18 MB at most), lines of the most
//              expensive list queries at the 64-item bound, and queries beyond it
//   dashboard  a POST of 32 DRR? of the largest size: its turns, each under the mutex
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/socket.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "../support/http_client.hpp"
#include "piezoshift/host/dashboard.hpp"
#include "piezoshift/host/gcs_client.hpp"
#include "piezoshift/host/gcs_interpreter.hpp"
#include "piezoshift/host/line_server.hpp"
#include "piezoshift/plant/geometry.hpp"

namespace piezoshift::host {
namespace {

// One turn of a client may make at most: answers up to the output high-water mark, then the one
// line (or part) that crosses it.
constexpr std::size_t kTurnBytes =
    LineServerLimits{}.output_high_water_bytes + GcsInterpreter::kMaxPartBytes;

bool eventually(const std::function<bool()>& condition, double timeout_s = 20.0) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!condition()) {
    if (std::chrono::steady_clock::now() > end)
      return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

// The interpreter with every table recording and every point held: each DRR? is the largest.
struct FullRecorder {
  StageModel model{stage_model_params(plant::GeometryParams{})};
  runtime::HostLink link;
  GcsInterpreter gcs{model, link, 1e-3, GcsOptions{}};

  FullRecorder() {
    constexpr ClientId kSetup = 999;
    gcs.on_connect(kSetup);
    const char* sources[] = {"Z", "U", "V"};
    for (int t = 1; t <= DataRecorder::kTables; ++t)
      gcs.on_line(kSetup, fmt_drc(t, sources[(t - 1) % 3]));
    gcs.on_disconnect(kSetup);
    for (std::uint64_t k = 0; k < DataRecorder::kPoints;) {
      for (int i = 0; i < 512; ++i, ++k) {
        runtime::HostSample s{};
        s.tick = k;
        s.t_s = 1e-3 * static_cast<double>(k);
        // Long values: nine significant digits and an exponent in every column.
        s.sgs_V = {1.234567891 + 1e-7 * static_cast<double>(k), 2.345678912, 3.456789123};
        s.zd_um = {-1.23456789e-3, 2.3456789e-3, 3.456789e-3};
        link.samples.try_push(s);
      }
      gcs.drain();
    }
  }
  static std::string fmt_drc(int t, const char* source) {
    return "DRC " + std::to_string(t) + " " + source + " " + (t <= 3 ? "2" : "3");
  }
};

// Forwards to the interpreter; per round (on_poll starts one) sums the answer bytes made for
// the attacker, and for each of the victim's POS? the attacker's bytes in its round and the one
// before: what the POS? waited for.
class Counting final : public LineHandler {
 public:
  explicit Counting(GcsInterpreter& inner) : inner_(inner) {}
  std::atomic<ClientId> victim{0};
  std::atomic<int> pos_answered{0};
  std::atomic<int> pos_beside_the_flood{0};  // with attacker's answers made in their window
  std::atomic<std::uint64_t> attacker_bytes{0};
  // Read after the server has stopped.
  std::size_t most_in_one_round = 0;
  std::size_t most_before_a_pos = 0;

  void on_connect(ClientId id) override { inner_.on_connect(id); }
  void on_disconnect(ClientId id) override { inner_.on_disconnect(id); }
  std::string on_overlong_line(ClientId id) override { return inner_.on_overlong_line(id); }
  bool is_immediate(char b) const override { return inner_.is_immediate(b); }
  std::string on_immediate(ClientId id, char b) override {
    return count(id, inner_.on_immediate(id, b));
  }
  bool answer_pending(ClientId id) const override { return inner_.answer_pending(id); }
  std::string more_answer(ClientId id) override { return count(id, inner_.more_answer(id)); }
  void on_poll() override {
    most_in_one_round = std::max(most_in_one_round, this_round_);
    last_round_ = this_round_;
    this_round_ = 0;
    inner_.on_poll();
  }
  std::string on_line(ClientId id, std::string_view line) override {
    if (id == victim.load() && line == "POS?") {
      most_before_a_pos = std::max(most_before_a_pos, last_round_ + this_round_);
      pos_beside_the_flood += last_round_ + this_round_ > 0 ? 1 : 0;
      ++pos_answered;
    }
    return count(id, inner_.on_line(id, line));
  }

 private:
  std::string count(ClientId id, std::string answer) {
    if (id != victim.load()) {
      this_round_ += answer.size();
      attacker_bytes += answer.size();
    }
    return answer;
  }
  GcsInterpreter& inner_;
  std::size_t this_round_ = 0;
  std::size_t last_round_ = 0;
};

// Sends `flood` over and over and reads (and drops) every answer, so the server never throttles it.
class ReadingFlooder {
 public:
  ReadingFlooder(std::uint16_t port, std::string flood)
      : connection_(port), thread_([this, flood = std::move(flood)] { run(flood); }) {}
  ~ReadingFlooder() {
    stop_ = true;
    thread_.join();
  }
  ReadingFlooder(const ReadingFlooder&) = delete;
  ReadingFlooder& operator=(const ReadingFlooder&) = delete;
  std::uint64_t received() const { return received_.load(); }

 private:
  void run(const std::string& flood) {
    const int fd = connection_.fd();
    ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) | O_NONBLOCK);
    std::size_t at = 0;
    char buffer[65536];
    while (!stop_.load()) {
      pollfd p{fd, POLLIN | POLLOUT, 0};
      if (::poll(&p, 1, 10) <= 0)
        continue;
      if (p.revents & POLLIN) {
        const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
        if (n == 0 || (n < 0 && errno != EAGAIN && errno != EINTR))
          return;
        if (n > 0)
          received_ += static_cast<std::uint64_t>(n);
      }
      if (p.revents & POLLOUT) {
        const ssize_t n = ::send(fd, flood.data() + at, flood.size() - at, MSG_NOSIGNAL);
        if (n > 0)
          at = (at + static_cast<std::size_t>(n)) % flood.size();
      }
    }
  }
  testing::HttpConnection connection_;  // a plain TCP connection
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> received_{0};
  std::thread thread_;
};

// The worst lines within the limits: the largest DRR?, list queries at the 64-item bound (VEL
// set to 1e300 first: 300-digit values), and lists beyond the bound (refused, error 24).
std::string worst_gcs_flood() {
  std::string flood = "VEL Z 1e300 U 1e300 V 1e300\n";
  std::string vel = "VEL?";
  std::string too_many = "POS?";
  for (std::size_t i = 0; i < GcsInterpreter::kMaxQueryItems; ++i)
    vel += " Z";
  for (int i = 0; i < 2000; ++i)
    too_many += " U";
  for (int i = 0; i < 4; ++i)
    flood += "DRR?\n" + vel + "\n" + too_many + "\nERR?\n";
  return flood;
}

TEST(WorstClient, GcsFloodDelaysAnotherClientsPosByAtMostTwoTurns) {
  FullRecorder recorder;
  Counting counting(recorder.gcs);
  LineServer server(ListenAddress{"127.0.0.1", 0, false}, LineServerLimits{}, counting);
  std::thread running([&] { server.run(nullptr, 2); });
  {
    GcsClient victim("127.0.0.1", server.port());
    ASSERT_TRUE(victim.query("POS?").starts_with("Z="));  // connected: the first id
    counting.victim = 1;
    counting.pos_answered = 0;
    const ReadingFlooder attacker(server.port(), worst_gcs_flood());
    ASSERT_TRUE(
        eventually([&] { return attacker.received() > 4 * DataRecorder::kMaxAnswerBytes; }));
    for (int i = 0; i < 200; ++i)
      EXPECT_TRUE(victim.query("POS?").starts_with("Z="));
  }
  server.stop();
  running.join();
  EXPECT_EQ(counting.pos_answered.load(), 200);
  // The flood went on while the victim asked (else the bounds below would say nothing).
  EXPECT_GT(counting.pos_beside_the_flood.load(), 0);
  EXPECT_LE(counting.most_in_one_round, kTurnBytes);
  EXPECT_LE(counting.most_before_a_pos, 2 * kTurnBytes);
  // Before answers were made in parts, one DRR? alone was a turn of 1.18 MB.
  EXPECT_GT(counting.most_in_one_round, LineServerLimits{}.output_high_water_bytes / 2);
}

TEST(WorstClient, NoAnswerExceedsItsBoundsWhateverTheList) {
  FullRecorder recorder;
  constexpr ClientId kClient = 1;
  recorder.gcs.on_connect(kClient);
  std::string whole = recorder.gcs.on_line(kClient, "DRR?");
  EXPECT_LE(whole.size(), GcsInterpreter::kMaxPartBytes);
  int parts = 1;
  while (recorder.gcs.answer_pending(kClient)) {
    const std::string part = recorder.gcs.more_answer(kClient);
    EXPECT_LE(part.size(), GcsInterpreter::kMaxPartBytes);
    whole += part;
    ++parts;
  }
  EXPECT_EQ(parts, static_cast<int>(DataRecorder::kPoints * DataRecorder::kTables /
                                    DataRecorder::kValuesPerPart));
  EXPECT_LE(whole.size(), GcsInterpreter::kMaxAnswerBytes);
  EXPECT_EQ(std::count(whole.begin(), whole.end(), '\n'),
            static_cast<std::ptrdiff_t>(DataRecorder::kPoints + 16));  // 16 header lines
  ASSERT_EQ(recorder.gcs.on_line(kClient, "ERR?"), "0\n");

  recorder.gcs.on_line(kClient, "VEL Z 1e300");
  std::string at_bound = "VEL?";
  for (std::size_t i = 0; i < GcsInterpreter::kMaxQueryItems; ++i)
    at_bound += " Z";
  const std::string big = recorder.gcs.on_line(kClient, at_bound);
  EXPECT_EQ(std::count(big.begin(), big.end(), '\n'),
            static_cast<std::ptrdiff_t>(GcsInterpreter::kMaxQueryItems));
  EXPECT_LE(big.size(), GcsInterpreter::kMaxPartBytes);
  EXPECT_EQ(recorder.gcs.on_line(kClient, at_bound + " Z"), "\n");  // one item too many
  EXPECT_EQ(recorder.gcs.on_line(kClient, "ERR?"), "24\n");
}

std::string post_body(int lines, const std::string& line) {
  std::string body = "{\"commands\": [";
  for (int i = 0; i < lines; ++i)
    body += (i > 0 ? ",\"" : "\"") + line + "\"";
  return body + "]}";
}

HttpRequest post(std::uint64_t client, const std::string& body) {
  HttpRequest r;
  r.method = "POST";
  r.path = "/api/command";
  r.body = body;
  r.client = client;
  return r;
}

// One 8 kB POST of GCS lines once held the interpreter for 1.44 s. Now it runs in turns of
// at most kTurnBytes of answers, and a GCS client's line runs between any two.
TEST(WorstClient, DashboardPostRunsInTurnsOfBoundedWork) {
  FullRecorder recorder;
  std::mutex mutex;
  Dashboard dashboard(recorder.gcs, mutex, "<html></html>", DashboardOptions{});
  constexpr ClientId kGcsClient = 1;
  recorder.gcs.on_connect(kGcsClient);

  const HttpResponse first = dashboard.on_request(post(7, post_body(32, "DRR?")));
  ASSERT_TRUE(first.later);
  int turns = 0;
  std::size_t most_in_a_turn = 0;
  HttpResponse r = first;
  while (r.later && turns < 10000) {
    const std::uint64_t before = recorder.gcs.stats().answer_bytes;
    r = dashboard.resume(7);
    ++turns;
    most_in_a_turn =
        std::max<std::size_t>(most_in_a_turn, recorder.gcs.stats().answer_bytes - before);
    // The GCS client between two turns: answered at once.
    EXPECT_TRUE(recorder.gcs.on_line(kGcsClient, "POS?").starts_with("Z="));
  }
  EXPECT_LE(most_in_a_turn, kTurnBytes);
  // 2 MiB of answers end it: the first DRR? whole, the second cut short.
  EXPECT_EQ(r.status, 413);
  EXPECT_NE(r.body.find("exceed 2097152 bytes"), std::string::npos) << r.body.substr(0, 200);
  EXPECT_GT(turns, 16);
  EXPECT_LE(r.body.size(), DashboardOptions{}.max_answer_bytes + 64 * 1024);

  // Small POSTs are unchanged: every answer, in one turn.
  const HttpResponse small = dashboard.on_request(post(8, post_body(2, "POS? Z")));
  ASSERT_TRUE(small.later);
  const HttpResponse done = dashboard.resume(8);
  EXPECT_FALSE(done.later);
  EXPECT_EQ(done.status, 200);
  EXPECT_NE(done.body.find("\"ok\":true"), std::string::npos) << done.body;
}

}  // namespace
}  // namespace piezoshift::host
