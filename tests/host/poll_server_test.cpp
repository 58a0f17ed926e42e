// The poll server's shared rules (poll_server.hpp), pinned for both protocols on it, the GCS
// LineServer and the dashboard's HttpServer, over loopback:
//   fairness   a client that floods is served at most one budget per round (LineServer: 32
//              lines, HttpServer: 16 KiB read), so another client's answer waits for at most two
//              budgets of the flooder's work: the rest of the round its bytes arrive in, and the
//              round that reads them. Counted in the server's own rounds and bytes, never timed:
//              the machine is shared.
//   slow       a reader that never reads is evicted once its send queue exceeds its bound (and
//              counted), while another client keeps being answered.
//   refusal    a connection beyond max_clients is refused and counted on both.
//   room       with the table full, a newcomer takes the place of the client whose line or
//              request head has been incomplete longest (2 s at least: clients sending
//              a byte every 0.9 s refused 196 of 198 newcomers), else of the client silent
//              longest (eight silent GCS clients once locked everyone out for the 600 s idle
//              timeout); event streams leave slots for requests (sixteen streams made every
//              other dashboard request a 503).
// Descriptor exhaustion (the accept back-off) is pinned for both in line_server_test.cpp and
// http_server_test.cpp (OutOfDescriptorsItPausesAcceptingAndServesTheClientsItHas).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "../support/http_client.hpp"
#include "piezoshift/host/gcs_client.hpp"
#include "piezoshift/host/http_server.hpp"
#include "piezoshift/host/line_server.hpp"

namespace piezoshift::host {
namespace {

using testing::http_status;
using testing::HttpConnection;

// Waits (an upper bound against hangs, not a speed assert) until condition holds.
bool eventually(const std::function<bool()>& condition, double timeout_s = 10.0) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!condition()) {
    if (std::chrono::steady_clock::now() > end)
      return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

// Runs a server's run() on its own thread; stops and joins on destruction.
template <class Server>
class Running {
 public:
  explicit Running(Server& server)
      : server_(server), thread_([this] { server_.run(nullptr, 2); }) {}
  ~Running() {
    server_.stop();
    thread_.join();
  }
  Running(const Running&) = delete;
  Running& operator=(const Running&) = delete;

 private:
  Server& server_;
  std::thread thread_;
};

// Sends prefix once, then pattern over and over until destroyed, and never reads: its socket
// buffers stay full, so the server always has more of it than one round's budget.
class Flooder {
 public:
  Flooder(std::uint16_t port, std::string prefix, const std::string& pattern)
      : connection_(port), thread_([this, prefix = std::move(prefix), pattern] {
          const int fd = connection_.fd();
          ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) | O_NONBLOCK);
          std::string chunk = prefix;
          while (chunk.size() < 65536 + prefix.size())
            chunk += pattern;
          std::size_t at = 0;
          while (!stop_.load()) {
            pollfd p{fd, POLLOUT, 0};
            if (::poll(&p, 1, 10) <= 0)
              continue;
            const ssize_t n = ::send(fd, chunk.data() + at, chunk.size() - at, MSG_NOSIGNAL);
            if (n < 0 && errno != EAGAIN && errno != EINTR)
              return;  // the server closed it
            if (n > 0) {
              sent_ += static_cast<std::uint64_t>(n);
              at += static_cast<std::size_t>(n);
            }
            if (at == chunk.size()) {
              chunk.erase(0, prefix.size());  // the prefix is sent once
              at = 0;
            }
          }
        }) {}
  ~Flooder() {
    stop_ = true;
    thread_.join();
  }
  Flooder(const Flooder&) = delete;
  Flooder& operator=(const Flooder&) = delete;
  std::uint64_t sent() const { return sent_.load(); }

 private:
  HttpConnection connection_;  // a plain TCP connection; nothing HTTP about it
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> sent_{0};
  std::thread thread_;
};

// ---- LineServer ----

// "F" (the flood: no answer), "ECHO x" -> "x\n", "BIG n" -> n bytes. Counts per round (on_poll
// starts one) the flood lines handled, and for each ECHO the flood lines handled in its round
// and the round before.
class LineCounting final : public LineHandler {
 public:
  // Read after the server has stopped, or through the atomics.
  std::atomic<std::uint64_t> flood_lines{0};
  std::atomic<int> disconnects{0};
  int most_flood_in_one_round = 0;
  int most_flood_before_an_echo = 0;
  int echoes_beside_the_flood = 0;  // ECHOs with flood lines handled in their window

  void on_disconnect(ClientId) override { ++disconnects; }
  void on_poll() override {
    most_flood_in_one_round = std::max(most_flood_in_one_round, flood_this_round_);
    flood_last_round_ = flood_this_round_;
    flood_this_round_ = 0;
  }
  std::string on_line(ClientId, std::string_view line) override {
    if (line == "F") {
      ++flood_this_round_;
      ++flood_lines;
      return {};
    }
    if (line.starts_with("ECHO ")) {
      const int window = flood_last_round_ + flood_this_round_;
      most_flood_before_an_echo = std::max(most_flood_before_an_echo, window);
      echoes_beside_the_flood += window > 0 ? 1 : 0;
      return std::string(line.substr(5)) + "\n";
    }
    if (line.starts_with("BIG "))
      return std::string(std::stoul(std::string(line.substr(4))) - 1, 'x') + "\n";
    return "?\n";
  }

 private:
  int flood_this_round_ = 0;
  int flood_last_round_ = 0;
};

TEST(PollServerFairness, LineFloodDelaysAnotherClientByAtMostTwoRoundsOfLines) {
  LineCounting handler;
  LineServer server(ListenAddress{"127.0.0.1", 0, false}, LineServerLimits{}, handler);
  std::uint64_t flood_handled_during_echoes = 0;
  {
    Running running(server);
    // The flooder first: within a round it is served before the other.
    const Flooder flooder(server.port(), "", "F\n");
    ASSERT_TRUE(eventually([&] { return server.client_count() == 1; }));
    GcsClient other("127.0.0.1", server.port());
    // More flood than one round takes is waiting before the first ECHO.
    ASSERT_TRUE(eventually([&] {
      return handler.flood_lines.load() > 4 * LineServer::kLinesPerTurn &&
             flooder.sent() > 2 * LineServer::kReadChunkBytes;
    }));
    const std::uint64_t before = handler.flood_lines.load();
    int correct = 0;
    for (int i = 0; i < 50; ++i)
      correct += other.query("ECHO " + std::to_string(i)) == std::to_string(i) + "\n" ? 1 : 0;
    EXPECT_EQ(correct, 50);
    flood_handled_during_echoes = handler.flood_lines.load() - before;
  }
  // The flood is served at its budget per round, no more: and the budget binds (it had more).
  EXPECT_EQ(handler.most_flood_in_one_round, static_cast<int>(LineServer::kLinesPerTurn));
  // An ECHO waits for the rest of the round it arrived in and its own: 2 x 32 flood lines.
  EXPECT_LE(handler.most_flood_before_an_echo, static_cast<int>(2 * LineServer::kLinesPerTurn));
  // Not vacuous: the flood was being served beside the ECHOs.
  EXPECT_GT(flood_handled_during_echoes, 0u);
  EXPECT_GE(handler.echoes_beside_the_flood, 1);
}

// The turn's time budget (1 ms by default) ends a turn after the line that crosses it: with a
// budget of 1 ns every turn is that one line, however cheap, so the count, not a clock, shows it.
TEST(PollServerFairness, LineTurnEndsOnceItsTimeIsSpent) {
  LineCounting handler;
  LineServerLimits limits;
  limits.turn_budget_s = 1e-9;
  LineServer server(ListenAddress{"127.0.0.1", 0, false}, limits, handler);
  {
    Running running(server);
    const Flooder flooder(server.port(), "", "F\n");
    ASSERT_TRUE(eventually([&] { return handler.flood_lines.load() > 100; }));
    GcsClient other("127.0.0.1", server.port());
    EXPECT_EQ(other.query("ECHO 1"), "1\n");
  }
  EXPECT_EQ(handler.most_flood_in_one_round, 1);
  EXPECT_LE(handler.most_flood_before_an_echo, 2);
}

TEST(PollServerSlowReader, LineReaderWhoseQueueExceedsTheBoundIsEvicted) {
  LineCounting handler;
  LineServerLimits limits;
  limits.max_pending_output_bytes = 1u << 20;
  // Only the queue bound may evict here, not the send timeout.
  limits.send_timeout_s = std::numeric_limits<double>::infinity();
  LineServer server(ListenAddress{"127.0.0.1", 0, false}, limits, handler);
  Running running(server);
  GcsClient slow("127.0.0.1", server.port());
  GcsClient other("127.0.0.1", server.port());
  EXPECT_EQ(other.query("ECHO before"), "before\n");

  // 48 MiB: more than the kernel's socket buffers take (tcp_wmem + tcp_rmem, a few MiB here;
  // at most 4 + 32 MiB by the usual maxima) plus the 1 MiB bound.
  constexpr std::size_t kAnswerBytes = std::size_t{48} << 20;
  slow.send("BIG " + std::to_string(kAnswerBytes));
  ASSERT_TRUE(eventually([&] { return server.stats().disconnected_slow == 1; }));
  EXPECT_EQ(other.query("ECHO after"), "after\n");
  EXPECT_TRUE(slow.wait_closed(10.0));
  ASSERT_TRUE(eventually([&] { return handler.disconnects.load() == 1; }));
  EXPECT_EQ(server.client_count(), 1u);
  const LineServerStats stats = server.stats();
  EXPECT_EQ(stats.disconnected_slow, 1u);
  EXPECT_EQ(stats.disconnected_idle, 0u);
  EXPECT_LT(stats.bytes_out, kAnswerBytes - limits.max_pending_output_bytes);
}

TEST(PollServerRefusal, LineConnectionBeyondMaxClientsIsCounted) {
  LineCounting handler;
  LineServerLimits limits;
  limits.max_clients = 1;
  limits.evict_idle_when_full_s = std::numeric_limits<double>::infinity();  // the refusal alone
  LineServer server(ListenAddress{"127.0.0.1", 0, false}, limits, handler);
  Running running(server);
  GcsClient first("127.0.0.1", server.port());
  EXPECT_EQ(first.query("ECHO 1"), "1\n");
  GcsClient second("127.0.0.1", server.port());
  EXPECT_TRUE(second.wait_closed(10.0));
  EXPECT_EQ(server.stats().refused_max_clients, 1u);
  EXPECT_EQ(server.stats().accepted, 1u);
}

// Eight GCS clients that connect and say nothing once held every slot until the idle
// timeout. Now a ninth takes the place of the one silent longest, the first.
TEST(PollServerRoom, LineSilentClientsGiveWayToANewcomer) {
  LineCounting handler;
  LineServerLimits limits;              // max_clients 8
  limits.evict_idle_when_full_s = 0.0;  // silent at all is enough (default: 1 s of silence)
  LineServer server(ListenAddress{"127.0.0.1", 0, false}, limits, handler);
  Running running(server);
  std::vector<std::unique_ptr<GcsClient>> silent;
  for (std::size_t i = 0; i < limits.max_clients; ++i) {
    silent.push_back(std::make_unique<GcsClient>("127.0.0.1", server.port()));
    // One at a time, so that the first is the one silent longest.
    ASSERT_TRUE(eventually([&] { return server.client_count() == i + 1; }));
  }
  GcsClient ninth("127.0.0.1", server.port());
  EXPECT_EQ(ninth.query("ECHO 9"), "9\n");
  EXPECT_TRUE(silent.front()->wait_closed(10.0));
  EXPECT_EQ(server.stats().evicted_for_room, 1u);
  EXPECT_EQ(server.stats().refused_max_clients, 0u);
  EXPECT_EQ(server.client_count(), limits.max_clients);
  // The others kept their places.
  for (std::size_t i = 1; i < silent.size(); ++i)
    EXPECT_EQ(silent[i]->query("ECHO " + std::to_string(i)), std::to_string(i) + "\n");
}

// A client that spoke more recently than evict_idle_when_full_s keeps its place: the newcomer
// is refused as before.
TEST(PollServerRoom, LineRecentlyActiveClientKeepsItsPlace) {
  LineCounting handler;
  LineServerLimits limits;
  limits.max_clients = 1;
  limits.evict_idle_when_full_s = 3600.0;
  LineServer server(ListenAddress{"127.0.0.1", 0, false}, limits, handler);
  Running running(server);
  GcsClient first("127.0.0.1", server.port());
  EXPECT_EQ(first.query("ECHO 1"), "1\n");
  GcsClient second("127.0.0.1", server.port());
  EXPECT_TRUE(second.wait_closed(10.0));
  EXPECT_EQ(first.query("ECHO 2"), "2\n");
  EXPECT_EQ(server.stats().evicted_for_room, 0u);
  EXPECT_EQ(server.stats().refused_max_clients, 1u);
}

// Sends `first` at once, then one byte of `pattern` (cyclically) every period_s until destroyed:
// a client that is never silent for a second and never completes its line or request head.
class Trickler {
 public:
  Trickler(std::uint16_t port, std::string first, std::string pattern, double period_s)
      : connection_(port), thread_([this, first = std::move(first), pattern, period_s] {
          connection_.send(first);
          sent_first_ = true;
          for (std::size_t i = 0; !stop_.load(); ++i) {
            const auto until =
                std::chrono::steady_clock::now() + std::chrono::duration<double>(period_s);
            while (!stop_.load() && std::chrono::steady_clock::now() < until)
              std::this_thread::sleep_for(std::chrono::milliseconds(5));
            if (!stop_.load())
              connection_.send(std::string(1, pattern[i % pattern.size()]));
          }
        }) {}
  ~Trickler() {
    stop_ = true;
    thread_.join();
  }
  Trickler(const Trickler&) = delete;
  Trickler& operator=(const Trickler&) = delete;
  bool sent_first() const { return sent_first_.load(); }
  //! True once the server has closed the connection (EOF or reset), within timeout_s.
  bool closed(double timeout_s) {
    std::string ignored;
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (std::chrono::steady_clock::now() < end)
      if (!connection_.read_some(ignored, 0.05))
        return true;
    return false;
  }

 private:
  HttpConnection connection_;  // a plain TCP connection
  std::atomic<bool> stop_{false};
  std::atomic<bool> sent_first_{false};
  std::thread thread_;
};

// Eight GCS clients sending a byte every 0.9 s are never silent for the 1 s that makes
// a client give way, and refused 196 of 198 newcomers. A client whose line is incomplete 2 s
// after its first byte (evict_incomplete_when_full_s) now gives way first, the oldest line first.
// The bound is a lower one: waiting longer on a loaded machine changes nothing.
TEST(PollServerRoom, LineClientsThatNeverEndALineGiveWayToNewcomers) {
  LineCounting handler;
  LineServerLimits limits;  // max_clients 8, evict_idle_when_full_s 1, incomplete 2
  LineServer server(ListenAddress{"127.0.0.1", 0, false}, limits, handler);
  Running running(server);
  std::vector<std::unique_ptr<Trickler>> slow;
  for (std::size_t i = 0; i < limits.max_clients; ++i) {
    slow.push_back(std::make_unique<Trickler>(server.port(), "E", "CHO", 0.3));
    ASSERT_TRUE(
        eventually([&] { return server.client_count() == i + 1 && slow[i]->sent_first(); }));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(2200));
  std::vector<std::unique_ptr<GcsClient>> newcomers;  // each kept: each takes a place
  for (int n = 0; n < 3; ++n) {
    newcomers.push_back(std::make_unique<GcsClient>("127.0.0.1", server.port()));
    EXPECT_EQ(newcomers.back()->query("ECHO " + std::to_string(n)), std::to_string(n) + "\n");
  }
  EXPECT_TRUE(slow[0]->closed(10.0));  // the oldest line went first
  EXPECT_GE(server.stats().evicted_for_room, 3u);
  EXPECT_EQ(server.stats().refused_max_clients, 0u);
}

// Clients that complete their lines keep their places, however long they stay: the newcomer is
// refused (the idle rule set aside, so that only the incomplete-line rule could choose).
TEST(PollServerRoom, LineClientsThatEndTheirLinesKeepTheirPlaces) {
  LineCounting handler;
  LineServerLimits limits;
  limits.max_clients = 2;
  limits.evict_idle_when_full_s = std::numeric_limits<double>::infinity();
  LineServer server(ListenAddress{"127.0.0.1", 0, false}, limits, handler);
  Running running(server);
  GcsClient a("127.0.0.1", server.port());
  GcsClient b("127.0.0.1", server.port());
  EXPECT_EQ(a.query("ECHO a"), "a\n");
  EXPECT_EQ(b.query("ECHO b"), "b\n");
  std::this_thread::sleep_for(std::chrono::milliseconds(2200));
  GcsClient c("127.0.0.1", server.port());
  EXPECT_TRUE(c.wait_closed(10.0));
  EXPECT_EQ(a.query("ECHO a"), "a\n");
  EXPECT_EQ(server.stats().evicted_for_room, 0u);
  EXPECT_EQ(server.stats().refused_max_clients, 1u);
}

// ---- HttpServer ----

// "/" -> 200 "ok", "/stream" -> an event stream. Records per round (on_poll starts one) the bytes
// read, and for each "/" the bytes read in its round so far and the round before; broadcasts
// 64 KiB per round while `broadcasting`.
class HttpCounting final : public HttpHandler {
 public:
  std::atomic<bool> broadcasting{false};
  std::atomic<std::size_t> streams{0};
  // Read after the server has stopped.
  std::uint64_t most_bytes_in_one_round = 0;
  std::uint64_t most_bytes_before_an_answer = 0;
  int answers_beside_the_flood = 0;  // with more read in their window than their own request

  HttpResponse on_request(const HttpRequest& r) override {
    if (r.path == "/stream") {
      HttpResponse s;
      s.stream = true;
      s.body = "retry: 1000\n\n";
      return s;
    }
    const std::uint64_t window = server_->stats().bytes_in - bytes_at_last_round_;
    most_bytes_before_an_answer = std::max(most_bytes_before_an_answer, window);
    answers_beside_the_flood += window > kRequestBytes ? 1 : 0;
    return HttpResponse::text(200, "ok");
  }
  void on_poll(HttpServer& server) override {
    server_ = &server;
    const std::uint64_t now = server.stats().bytes_in;
    most_bytes_in_one_round = std::max(most_bytes_in_one_round, now - bytes_at_this_round_);
    bytes_at_last_round_ = bytes_at_this_round_;
    bytes_at_this_round_ = now;
    streams = server.stream_count();
    if (broadcasting)
      server.broadcast("data: " + std::string(64 * 1024, 'b') + "\n\n");
  }
  // Upper bound of one test request ("GET / HTTP/1.1", Host).
  static constexpr std::uint64_t kRequestBytes = 128;

 private:
  HttpServer* server_ = nullptr;
  std::uint64_t bytes_at_this_round_ = 0;
  std::uint64_t bytes_at_last_round_ = 0;
};

std::string get_root(std::uint16_t port) {
  return "GET / HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) + "\r\n\r\n";
}

// HTTP takes one request per connection, so the flood that can go on is the bytes of an open
// event stream's peer, which the server reads (for the peer's hang-up) and drops.
TEST(PollServerFairness, HttpFloodDelaysAnotherClientByAtMostTwoRoundsOfBytes) {
  HttpCounting handler;
  HttpServer server(HttpServerOptions{}, handler);
  std::uint64_t flood_sent = 0;
  {
    Running running(server);
    const std::string host = "Host: 127.0.0.1:" + std::to_string(server.port()) + "\r\n";
    const Flooder flooder(server.port(), "GET /stream HTTP/1.1\r\n" + host + "\r\n",
                          std::string(1000, 'f'));
    ASSERT_TRUE(eventually([&] {
      return handler.streams.load() == 1 &&
             server.stats().bytes_in > 8 * HttpServer::kReadChunkBytes;
    }));
    int answered = 0;
    for (int i = 0; i < 50; ++i) {
      const std::string request = get_root(server.port());
      ASSERT_LE(request.size(), HttpCounting::kRequestBytes);
      answered += http_status(testing::http_exchange(server.port(), request)) == 200 ? 1 : 0;
    }
    EXPECT_EQ(answered, 50);
    flood_sent = flooder.sent();
  }
  // One budget per client and round, and it binds: the flooder always had more waiting.
  EXPECT_GE(handler.most_bytes_in_one_round, HttpServer::kReadChunkBytes);
  EXPECT_LE(handler.most_bytes_in_one_round,
            HttpServer::kReadChunkBytes + HttpCounting::kRequestBytes);
  // An answer waits for at most two budgets of the flood: 2 x 16 KiB (+ its own request).
  EXPECT_LE(handler.most_bytes_before_an_answer,
            2 * HttpServer::kReadChunkBytes + HttpCounting::kRequestBytes);
  EXPECT_GE(handler.answers_beside_the_flood, 1);
  EXPECT_GT(flood_sent, 50 * HttpServer::kReadChunkBytes);
}

TEST(PollServerSlowReader, HttpStreamWhoseQueueExceedsTheBoundIsEvicted) {
  HttpCounting handler;
  HttpServerOptions options;
  options.max_pending_output_bytes = 256 * 1024;
  HttpServer server(options, handler);
  Running running(server);
  const std::string host = "Host: 127.0.0.1:" + std::to_string(server.port()) + "\r\n";
  HttpConnection slow(server.port());  // never reads
  slow.send("GET /stream HTTP/1.1\r\n" + host + "\r\n");
  ASSERT_TRUE(eventually([&] { return handler.streams.load() == 1; }));
  EXPECT_EQ(http_status(testing::http_exchange(server.port(), get_root(server.port()))), 200);

  // 64 KiB per round: the socket buffers fill, then the queue passes 256 KiB.
  handler.broadcasting = true;
  ASSERT_TRUE(eventually([&] { return server.stats().dropped_slow == 1; }));
  ASSERT_TRUE(eventually([&] { return handler.streams.load() == 0; }));
  handler.broadcasting = false;
  EXPECT_EQ(http_status(testing::http_exchange(server.port(), get_root(server.port()))), 200);
  const HttpServerStats stats = server.stats();
  EXPECT_EQ(stats.dropped_slow, 1u);
  EXPECT_EQ(stats.streams_opened, 1u);
  // It was sent less than it was given: the rest waited in its queue, over the bound.
  EXPECT_LT(stats.bytes_out, stats.broadcast_bytes);
}

TEST(PollServerRefusal, HttpConnectionBeyondMaxClientsGets503AndIsCounted) {
  HttpCounting handler;
  HttpServerOptions options;
  options.max_clients = 1;
  options.evict_idle_when_full_s = std::numeric_limits<double>::infinity();  // the refusal alone
  HttpServer server(options, handler);
  Running running(server);
  HttpConnection stream(server.port());
  stream.send("GET /stream HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(server.port()) +
              "\r\n\r\n");
  ASSERT_TRUE(eventually([&] { return handler.streams.load() == 1; }));
  EXPECT_EQ(http_status(testing::http_exchange(server.port(), get_root(server.port()))), 503);
  EXPECT_EQ(server.stats().refused_max_clients, 1u);
}

// Opens one event stream; its status (200, or 503 when streams have no slot left).
int open_stream(HttpConnection& c, std::uint16_t port) {
  c.send("GET /stream HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(port) + "\r\n\r\n");
  std::string got;
  for (int i = 0; i < 100 && got.find("\r\n\r\n") == std::string::npos; ++i)
    if (!c.read_some(got, 0.1))
      break;
  return http_status(got);
}

// Sixteen event streams, which never time out, once made every other request a 503. Streams
// may take all but reserved_for_requests (2) of the 16 slots; a GET is answered beside them.
TEST(PollServerRoom, HttpStreamsLeaveSlotsForRequests) {
  HttpCounting handler;
  HttpServerOptions options;  // 16 clients, 2 reserved for requests
  options.evict_idle_when_full_s = std::numeric_limits<double>::infinity();  // the reserve alone
  HttpServer server(options, handler);
  Running running(server);
  std::vector<std::unique_ptr<HttpConnection>> streams;
  int opened = 0;
  int refused = 0;
  for (std::size_t i = 0; i < options.max_clients; ++i) {
    streams.push_back(std::make_unique<HttpConnection>(server.port()));
    const int status = open_stream(*streams.back(), server.port());
    opened += status == 200 ? 1 : 0;
    refused += status == 503 ? 1 : 0;
  }
  EXPECT_EQ(opened, 14);
  EXPECT_EQ(refused, 2);
  EXPECT_EQ(http_status(testing::http_exchange(server.port(), get_root(server.port()))), 200);
  EXPECT_EQ(server.stats().refused_streams, 2u);
  EXPECT_EQ(server.stats().refused_max_clients, 0u);
}

// With no slot kept for requests, a full table of streams gives the longest-open one's place to
// a newcomer (EventSource reconnects by itself, after its retry).
TEST(PollServerRoom, HttpOldestStreamGivesWayWhenTheTableIsFull) {
  HttpCounting handler;
  HttpServerOptions options;
  options.reserved_for_requests = 0;
  options.evict_idle_when_full_s = 0.0;
  HttpServer server(options, handler);
  Running running(server);
  std::vector<std::unique_ptr<HttpConnection>> streams;
  for (std::size_t i = 0; i < options.max_clients; ++i) {
    streams.push_back(std::make_unique<HttpConnection>(server.port()));
    ASSERT_EQ(open_stream(*streams.back(), server.port()), 200);
  }
  ASSERT_TRUE(eventually([&] { return handler.streams.load() == options.max_clients; }));
  EXPECT_EQ(http_status(testing::http_exchange(server.port(), get_root(server.port()))), 200);
  EXPECT_EQ(server.stats().evicted_for_room, 1u);
  std::string rest;
  bool open = true;
  for (int i = 0; i < 100 && open; ++i)
    open = streams.front()->read_some(rest, 0.1);
  EXPECT_FALSE(open) << "the first stream was not the one closed";
}

// Sixteen HTTP clients sending one header line a second denied 81 % of another
// client's requests. A request whose head is incomplete 2 s after its first byte now gives way
// to a newcomer, whose GET is answered.
TEST(PollServerRoom, HttpClientsThatNeverEndTheirHeadGiveWayToNewcomers) {
  HttpCounting handler;
  HttpServerOptions o;  // max_clients 16, evict_idle_when_full_s 1, incomplete 2
  HttpServer server(o, handler);
  Running running(server);
  std::vector<std::unique_ptr<Trickler>> slow;
  for (std::size_t i = 0; i < o.max_clients; ++i) {
    slow.push_back(
        std::make_unique<Trickler>(server.port(), "GET / HTTP/1.1\r\n", "X-Slow: 1\r\n", 0.3));
    ASSERT_TRUE(eventually([&] { return slow[i]->sent_first(); }));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(2200));
  // Each answered request is closed, so the first newcomer's place serves the next ones too.
  for (int n = 0; n < 3; ++n)
    EXPECT_EQ(http_status(testing::http_exchange(server.port(), get_root(server.port()))), 200);
  EXPECT_GE(server.stats().evicted_for_room, 1u);
  EXPECT_EQ(server.stats().refused_max_clients, 0u);
}

}  // namespace
}  // namespace piezoshift::host
