// The TCP transport of `piezoshift serve` (LineServer) and the GCS client, over loopback: framing,
// several clients, resource limits (clients, line length, pending output, idle time), hostile
// input and peers that vanish mid-answer, a non-reading client that must not delay another (with
// the real GCS interpreter), address checks. SIGPIPE is deliberately NOT ignored in
// this process: a send() without MSG_NOSIGNAL to a vanished peer would kill the test.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "../support/descriptor_exhaustion.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/host/gcs_client.hpp"
#include "piezoshift/host/gcs_interpreter.hpp"
#include "piezoshift/host/line_server.hpp"
#include "piezoshift/host/locked_line_handler.hpp"
#include "piezoshift/plant/geometry.hpp"

namespace piezoshift::host {
namespace {

using namespace std::string_literals;

// A protocol small enough to reason about byte for byte:
//   ECHO x   -> "x\n"
//   MULTI n  -> n lines "line 1 \n" ... "line n\n" (GCS framing)
//   BIG n    -> n bytes: n-1 'x' and LF
//   ID       -> the client's id
//   SILENT   -> nothing
//   other    -> "UNKNOWN <length of the line in bytes>\n"
class TestHandler final : public LineHandler {
 public:
  std::atomic<int> connects{0}, disconnects{0}, overlongs{0}, polls{0}, big_lines{0};

  void on_connect(ClientId) override { ++connects; }
  void on_disconnect(ClientId) override { ++disconnects; }
  void on_poll() override { ++polls; }
  std::string on_overlong_line(ClientId) override {
    ++overlongs;
    return "OVERLONG\n";
  }
  // 0x05 is a single-character command, as GCS's #5.
  bool is_immediate(char byte) const override { return byte == 5; }
  std::string on_immediate(ClientId, char byte) override {
    return "IMMEDIATE " + std::to_string(int(byte)) + "\n";
  }
  std::string on_line(ClientId id, std::string_view line) override {
    {
      std::lock_guard lock(mutex_);
      lines_.emplace_back(line);
    }
    if (line.starts_with("ECHO "))
      return std::string(line.substr(5)) + "\n";
    if (line.starts_with("MULTI ")) {
      const int n = std::stoi(std::string(line.substr(6)));
      std::string answer;
      for (int i = 1; i <= n; ++i)
        answer += "line " + std::to_string(i) + (i < n ? " \n" : "\n");
      return answer;
    }
    if (line.starts_with("BIG ")) {
      ++big_lines;
      return std::string(std::stoul(std::string(line.substr(4))) - 1, 'x') + "\n";
    }
    if (line == "ID")
      return std::to_string(id) + "\n";
    if (line == "SILENT")
      return {};
    return "UNKNOWN " + std::to_string(line.size()) + "\n";
  }
  std::vector<std::string> lines() {
    std::lock_guard lock(mutex_);
    return lines_;
  }

 private:
  std::mutex mutex_;
  std::vector<std::string> lines_;
};

// A server on an ephemeral loopback port, running on its own thread until destruction.
class ServerThread {
 public:
  explicit ServerThread(LineHandler& handler, const LineServerLimits& limits = {})
      : server_(ListenAddress{"127.0.0.1", 0, false}, limits, handler), thread_([this] {
          try {
            server_.run();
          } catch (...) {
            error_ = std::current_exception();
          }
        }) {}
  ~ServerThread() { join(); }
  //! Stops the server and waits for run() to return (after it disconnected every client).
  void join() {
    if (!thread_.joinable())
      return;
    server_.stop();
    thread_.join();
    if (error_) {
      try {
        std::rethrow_exception(error_);
      } catch (const std::exception& e) {
        ADD_FAILURE() << "run() threw: " << e.what();
      }
    }
  }
  LineServer& server() { return server_; }
  std::uint16_t port() const { return server_.port(); }
  std::unique_ptr<GcsClient> connect() {
    return std::make_unique<GcsClient>("127.0.0.1", server_.port());
  }

 private:
  LineServer server_;
  std::exception_ptr error_;
  std::thread thread_;
};

// Waits (an upper bound against hangs, not a speed assert) until condition holds.
bool eventually(const std::function<bool()>& condition, double timeout_s = 5.0) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!condition()) {
    if (std::chrono::steady_clock::now() > end)
      return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

TEST(LineServerFraming, ASingleCharacterCommandNeedsNoLfWhereALineWouldStart) {
  TestHandler handler;
  ServerThread st(handler);
  auto c = st.connect();
  c->send_raw("\x05");  // no LF: answered at once
  EXPECT_EQ(c->read_answer(), "IMMEDIATE 5\n");
  // Twice in a row, then a line: three answers in order.
  c->send_raw(
      "\x05\x05"
      "ECHO a\n");
  EXPECT_EQ(c->read_answer(), "IMMEDIATE 5\n");
  EXPECT_EQ(c->read_answer(), "IMMEDIATE 5\n");
  EXPECT_EQ(c->read_answer(), "a\n");
  // Inside a line the byte belongs to the line (ECHO x<05>y is 8 bytes long).
  c->send_raw("ECHO x\x05y\n");
  EXPECT_EQ(c->read_answer(), "x\x05y\n");
  EXPECT_EQ(handler.lines().size(), 2u);
}

// `serve --http-port` puts the interpreter behind a mutex: single-character commands must pass.
TEST(LineServerFraming, ALockedHandlerPassesSingleCharacterCommandsOn) {
  TestHandler handler;
  std::mutex mutex;
  LockedLineHandler locked(handler, mutex);
  ServerThread st(locked);
  auto client = st.connect();
  client->send_raw("\x05");
  EXPECT_EQ(client->read_answer(), "IMMEDIATE 5\n");
  EXPECT_EQ(client->query("ECHO x"), "x\n");
}

TEST(LineServerFraming, MultiLineAnswerIsReadWholeWithItsLines) {
  TestHandler handler;
  ServerThread server(handler);
  auto client = server.connect();

  EXPECT_EQ(client->query("MULTI 3"), "line 1 \nline 2 \nline 3\n");
  const std::vector<std::string> lines = client->query_lines("MULTI 5");
  ASSERT_EQ(lines.size(), 5u);
  EXPECT_EQ(lines[0], "line 1");
  EXPECT_EQ(lines[4], "line 5");
  EXPECT_EQ(client->query_lines("MULTI 1"), std::vector<std::string>{"line 1"});
  // An empty line is a command too (the handler answers its length, 0).
  EXPECT_EQ(client->query(""), "UNKNOWN 0\n");
}

TEST(LineServerFraming, SeveralCommandsInOneSendAreAnsweredInOrder) {
  TestHandler handler;
  ServerThread server(handler);
  auto client = server.connect();

  client->send_raw("ECHO a\nMULTI 3\nSILENT\nECHO b\n");
  EXPECT_EQ(client->read_answer(), "a\n");
  EXPECT_EQ(client->read_answer_lines().size(), 3u);
  EXPECT_EQ(client->read_answer(), "b\n");  // SILENT answered nothing
  // A command split over two sends is one line.
  client->send_raw("ECH");
  client->send_raw("O split\n");
  EXPECT_EQ(client->read_answer(), "split\n");
  // CRLF: the CR is not part of the line (the echo has none), only one CR is removed.
  EXPECT_EQ(client->query("ECHO crlf\r"), "crlf\n");
  EXPECT_EQ(client->query("ECHO two\r\r"), "two\r\n");
  const std::vector<std::string> seen = handler.lines();
  ASSERT_EQ(seen.size(), 7u);
  EXPECT_EQ(seen[4], "ECHO split");
}

TEST(LineServerClients, InterleavedClientsEachGetTheirOwnAnswers) {
  TestHandler handler;
  ServerThread server(handler);
  constexpr int kClients = 5;
  constexpr int kRounds = 20;
  std::vector<std::unique_ptr<GcsClient>> clients;
  for (int i = 0; i < kClients; ++i)
    clients.push_back(server.connect());

  int correct = 0;
  for (int round = 0; round < kRounds; ++round) {
    // All send first, then all read: the server has every client's command at once.
    for (int i = 0; i < kClients; ++i)
      clients[i]->send("ECHO c" + std::to_string(i) + " r" + std::to_string(round));
    for (int i = 0; i < kClients; ++i)
      correct += clients[i]->read_answer() ==
                 "c" + std::to_string(i) + " r" + std::to_string(round) + "\n";
  }
  EXPECT_EQ(correct, kClients * kRounds);
  EXPECT_EQ(server.server().client_count(), 5u);

  // Client ids are unique and never reused, also across reconnections.
  std::set<std::string> ids;
  for (auto& c : clients)
    ids.insert(c->query("ID"));
  for (auto& c : clients)
    c->close();
  ASSERT_TRUE(eventually([&] { return handler.disconnects == kClients; }));
  for (auto& c : clients) {
    c = server.connect();
    ids.insert(c->query("ID"));
  }
  EXPECT_EQ(ids.size(), 10u);
  clients.clear();
  ASSERT_TRUE(eventually([&] { return handler.disconnects == 2 * kClients; }));
  EXPECT_EQ(handler.connects, 2 * kClients);
  EXPECT_EQ(server.server().client_count(), 0u);
  EXPECT_EQ(server.server().stats().accepted, 10u);
}

TEST(LineServerLimits, ConnectionBeyondMaxClientsIsClosedAtOnce) {
  TestHandler handler;
  LineServerLimits limits;
  limits.max_clients = 2;
  // The refusal itself: no silent client gives way (poll_server_test.cpp has that rule).
  limits.evict_idle_when_full_s = std::numeric_limits<double>::infinity();
  ServerThread server(handler, limits);
  auto first = server.connect();
  auto second = server.connect();
  // Served, hence accepted before the third connects.
  EXPECT_EQ(first->query("ECHO 1"), "1\n");
  EXPECT_EQ(second->query("ECHO 2"), "2\n");

  auto third = server.connect();  // the kernel completes the handshake; the server then closes
  EXPECT_TRUE(third->wait_closed(5.0));
  EXPECT_EQ(server.server().stats().refused_max_clients, 1u);
  EXPECT_EQ(first->query("ECHO still 1"), "still 1\n");
  EXPECT_EQ(second->query("ECHO still 2"), "still 2\n");
  EXPECT_EQ(handler.connects, 2);
  EXPECT_EQ(server.server().client_count(), 2u);

  // A freed slot is given to the next connection.
  first->close();
  ASSERT_TRUE(eventually([&] { return server.server().client_count() == 1; }));
  auto fourth = server.connect();
  EXPECT_EQ(fourth->query("ECHO 4"), "4\n");
  EXPECT_EQ(server.server().stats().accepted, 3u);
  EXPECT_EQ(server.server().stats().refused_max_clients, 1u);
}

TEST(LineServerLimits, OverlongLineIsReportedOnceAndItsRestDiscarded) {
  TestHandler handler;
  LineServerLimits limits;
  limits.max_line_bytes = 64;
  ServerThread server(handler, limits);
  auto client = server.connect();

  // 200 bytes of one line, including something that looks like a command: one OVERLONG only.
  client->send_raw(std::string(190, 'A') + "ECHO hidden\nECHO next\n");
  EXPECT_EQ(client->read_answer(), "OVERLONG\n");
  EXPECT_EQ(client->read_answer(), "next\n");

  // The boundary: 64 bytes pass (also followed by a CR, which does not count), 65 do not.
  const std::string payload59(59, 'p');  // "ECHO " + 59 = 64 bytes
  EXPECT_EQ(client->query("ECHO " + payload59), payload59 + "\n");
  EXPECT_EQ(client->query("ECHO " + payload59 + "\r"), payload59 + "\n");
  EXPECT_EQ(client->query("ECHO " + payload59 + "q"), "OVERLONG\n");

  // 100 000 bytes span several reads (64 KiB each): still reported once.
  client->send_raw(std::string(100000, 'B') + "\n");
  EXPECT_EQ(client->read_answer(), "OVERLONG\n");
  EXPECT_EQ(client->query("ECHO after"), "after\n");

  EXPECT_EQ(handler.overlongs, 3);
  EXPECT_EQ(server.server().stats().overlong_lines, 3u);
  for (const std::string& line : handler.lines())
    EXPECT_EQ(line.find("hidden"), std::string::npos);
  EXPECT_EQ(handler.lines().size(), 4u);  // next, two at 64 bytes, after
}

TEST(LineServerInput, GarbageBytesArePassedOnAsTheyAre) {
  TestHandler handler;
  ServerThread server(handler);
  auto client = server.connect();

  const std::string nul_ff_cr = "\0\xff\x01\rx"s;  // NUL, 0xFF, a lone CR inside the line
  client->send_raw(nul_ff_cr + "\n");
  EXPECT_EQ(client->read_answer(), "UNKNOWN 5\n");
  client->send_raw("\r\r\n");  // one trailing CR is removed, the other is the line
  EXPECT_EQ(client->read_answer(), "UNKNOWN 1\n");
  client->send_raw("\r");  // a lone CR never ends a line: joined to the next one
  client->send_raw("\xfe\xfd\n");
  EXPECT_EQ(client->read_answer(), "UNKNOWN 3\n");
  EXPECT_EQ(client->query("ECHO ok"), "ok\n");

  const std::vector<std::string> seen = handler.lines();
  ASSERT_EQ(seen.size(), 4u);
  EXPECT_EQ(seen[0], nul_ff_cr);
  EXPECT_EQ(seen[1], "\r");
  EXPECT_EQ(seen[2], "\r\xfe\xfd");
}

TEST(LineServerPeers, ClientVanishingMidAnswerDoesNotHurtTheServer) {
  TestHandler handler;
  ServerThread server(handler);
  constexpr std::size_t kAnswerBytes = 12u << 20;  // more than a socket buffer takes
  const std::string big = "BIG " + std::to_string(kAnswerBytes);

  // Closes at once: the server sees EOF, keeps sending the answer, the peer's kernel resets.
  {
    auto client = server.connect();
    client->send(big);
  }
  ASSERT_TRUE(eventually([&] { return handler.disconnects == 1; }));
  const std::uint64_t first_bytes = server.server().stats().bytes_out;

  // Closes while the answer is streaming in (unread data: reset right away).
  {
    auto client = server.connect();
    const std::uint64_t before = server.server().stats().bytes_out;
    client->send(big);
    ASSERT_TRUE(eventually([&] { return server.server().stats().bytes_out > before; }));
  }
  ASSERT_TRUE(eventually([&] { return handler.disconnects == 2; }));

  auto other = server.connect();
  EXPECT_EQ(other->query("ECHO alive"), "alive\n");
  const LineServerStats stats = server.server().stats();
  EXPECT_EQ(handler.big_lines, 2);
  // Neither answer was sent whole (the kernel takes a few MiB at most).
  EXPECT_GT(first_bytes, 0u);
  EXPECT_LT(first_bytes, kAnswerBytes);
  EXPECT_LT(stats.bytes_out - first_bytes, kAnswerBytes + 6);  // + "alive\n"
  EXPECT_EQ(stats.disconnected_slow, 0u);                      // a vanished peer is not a slow one
  EXPECT_EQ(server.server().client_count(), 1u);
}

TEST(LineServerLimits, SlowReaderIsDisconnectedWhileOthersAreServed) {
  TestHandler handler;
  LineServerLimits limits;
  limits.max_pending_output_bytes = 1u << 20;
  limits.send_timeout_s = 0.3;
  ServerThread server(handler, limits);
  auto slow = server.connect();
  auto fast = server.connect();

  // 256 answers of 256 KiB (64 MiB) that are never read.
  std::string requests;
  for (int i = 0; i < 256; ++i)
    requests += "BIG 262144\n";
  slow->send_raw(requests);

  int correct = 0;
  for (int i = 0; i < 20; ++i)
    correct += fast->query("ECHO " + std::to_string(i)) == std::to_string(i) + "\n";
  ASSERT_TRUE(eventually([&] { return server.server().stats().disconnected_slow == 1; }));
  for (int i = 20; i < 40; ++i)
    correct += fast->query("ECHO " + std::to_string(i)) == std::to_string(i) + "\n";
  EXPECT_EQ(correct, 40);

  EXPECT_TRUE(slow->wait_closed(5.0));
  ASSERT_TRUE(eventually([&] { return handler.disconnects == 1; }));
  EXPECT_EQ(server.server().client_count(), 1u);
  // Throttled, then cut off: answers were made only while its queue was short (a few socket
  // buffers' worth), never the 64 MiB.
  EXPECT_LT(handler.big_lines, 64);
  EXPECT_LT(server.server().stats().bytes_out, 32u << 20);
}

// Counts, per turn of the server's loop (on_poll() starts one), the DRR? answers made, and how
// many a POS? waited for; forwards everything to the GCS interpreter.
class TurnCountingHandler final : public LineHandler {
 public:
  explicit TurnCountingHandler(LineHandler& inner) : inner_(inner) {}
  std::atomic<int> drr_total{0};
  std::atomic<int> flood_end{0};  // drr_total once the current burst is all made
  // Read after the server has stopped (written by its thread only).
  int pos_answered = 0;
  int most_drr_in_one_turn = 0;
  int most_drr_before_a_pos = 0;       // in the POS?'s turn and the turn before it
  int pos_while_flood_unfinished = 0;  // POS? answered with some of the burst not yet made

  void on_connect(ClientId id) override { inner_.on_connect(id); }
  void on_disconnect(ClientId id) override { inner_.on_disconnect(id); }
  std::string on_overlong_line(ClientId id) override { return inner_.on_overlong_line(id); }
  bool is_immediate(char byte) const override { return inner_.is_immediate(byte); }
  std::string on_immediate(ClientId id, char byte) override {
    return inner_.on_immediate(id, byte);
  }
  void on_poll() override {
    most_drr_in_one_turn = std::max(most_drr_in_one_turn, drr_this_turn_);
    drr_last_turn_ = drr_this_turn_;
    drr_this_turn_ = 0;
    inner_.on_poll();
  }
  std::string on_line(ClientId id, std::string_view line) override {
    if (line == "DRR?") {
      ++drr_this_turn_;
      ++drr_total;
    } else if (line == "POS?") {
      most_drr_before_a_pos = std::max(most_drr_before_a_pos, drr_last_turn_ + drr_this_turn_);
      pos_while_flood_unfinished += drr_total.load() < flood_end.load();
      ++pos_answered;
    }
    return inner_.on_line(id, line);
  }

 private:
  LineHandler& inner_;
  int drr_this_turn_ = 0;
  int drr_last_turn_ = 0;
};

// One client sends 100 DRR? (each a full table of the recorder) and reads nothing; the
// POS? of another client right after must not wait for those answers to be made. Before the
// per-client throttle the server made kLinesPerTurn (32) answers of the burst in one turn, and a
// POS? arriving meanwhile waited for all of them. What is asserted is counted in the server's
// own turns, not timed: on the shared machines a latency in ms is the scheduler's (the median of
// 7 rounds once took 12 ms under the sanitizers, with the throttle working).
TEST(LineServerClients, NonReadingDrrFloodDoesNotDelayAnotherClientsPos) {
  const StageModel model(stage_model_params(plant::GeometryParams{}));
  runtime::HostLink link;
  GcsInterpreter gcs(model, link, 1e-3, GcsOptions{});
  // 2048 ticks recorded in tables 1 and 2 (the defaults), pushed as the loop would: each DRR? is
  // ~28 kB, above the 16 KiB output high-water mark, so one answer throttles its client.
  for (std::uint64_t k = 0; k < 2048; ++k) {
    runtime::HostSample s{};
    s.tick = k;
    s.t_s = 1e-3 * static_cast<double>(k);
    s.sgs_V = {1.0 + 1e-4 * static_cast<double>(k), 2.0, 3.0};
    ASSERT_TRUE(link.samples.try_push(s));
  }
  gcs.drain();
  TurnCountingHandler counting(gcs);
  LineServerLimits limits;
  limits.send_timeout_s = 1.0;
  ServerThread server(counting, limits);
  auto reader = server.connect();
  ASSERT_EQ(reader->query("DRL? 1"), "1=2048\n");
  const std::size_t drr_bytes = reader->query("DRR?").size();
  ASSERT_GT(drr_bytes, 25'000u);  // each answer of the flood costs real formatting work
  ASSERT_GT(drr_bytes, limits.output_high_water_bytes);

  constexpr int kBurst = 100;
  std::string flood;
  for (int i = 0; i < kBurst; ++i)
    flood += "DRR?\n";
  constexpr int kRounds = 7;
  for (int round = 0; round < kRounds; ++round) {
    auto flooder = server.connect();
    ASSERT_TRUE(eventually([&] { return server.server().client_count() == 2; }));
    const int before = counting.drr_total.load();
    counting.flood_end = before + kBurst;
    flooder->send_raw(flood);
    // The server has the burst and is making it when the POS? is sent.
    ASSERT_TRUE(eventually([&] { return counting.drr_total.load() > before; }));
    const std::string pos = reader->query("POS?");
    EXPECT_TRUE(pos.starts_with("Z=")) << pos;
    if (round + 1 < kRounds) {  // the last one stays, unread, for the send timeout
      flooder.reset();
      ASSERT_TRUE(eventually([&] { return server.server().client_count() == 1; }));
    } else {
      // 500 more: more answers than the sockets' buffers hold, so its queue stops draining.
      for (int i = 0; i < 5; ++i)
        flooder->send_raw(flood);
      EXPECT_TRUE(eventually([&] { return server.server().client_count() == 1; }));
    }
  }
  const LineServerStats stats = server.server().stats();
  server.join();
  EXPECT_EQ(counting.pos_answered, kRounds);
  // One answer of a burst per turn: it passes the high-water mark and throttles the flooder.
  EXPECT_EQ(counting.most_drr_in_one_turn, 1);
  // A POS? waits for the rest of the turn it arrived in and for the start of its own: at most one
  // answer of the burst in each.
  EXPECT_LE(counting.most_drr_before_a_pos, 2);
  // Not vacuous: in some rounds the burst was still being made when the POS? was answered.
  EXPECT_GE(counting.pos_while_flood_unfinished, 1);
  EXPECT_EQ(stats.disconnected_slow, 1u);  // the flooder left unread, after send_timeout_s
  // Throttled: of the 1200 DRR? sent, only what the sockets' buffers took was made.
  EXPECT_LT(gcs.stats().lines, 1100u);
}

TEST(LineServerLimits, IdleClientIsDisconnected) {
  TestHandler handler;
  LineServerLimits limits;
  limits.idle_timeout_s = 0.2;
  ServerThread server(handler, limits);
  auto idle = server.connect();

  EXPECT_TRUE(idle->wait_closed(5.0));
  ASSERT_TRUE(eventually([&] { return handler.disconnects == 1; }));
  EXPECT_EQ(server.server().stats().disconnected_idle, 1u);
  EXPECT_EQ(server.server().stats().disconnected_slow, 0u);
  EXPECT_EQ(server.server().client_count(), 0u);
}

TEST(LineServerLifecycle, StopFlagEndsRunAndDisconnectsEveryClient) {
  TestHandler handler;
  LineServer server(ListenAddress{"localhost", 0, false}, LineServerLimits{}, handler);
  std::atomic<int> stop_flag{0};
  std::thread thread([&] { server.run(&stop_flag); });

  GcsClient a("127.0.0.1", server.port());
  GcsClient b("localhost", server.port());
  EXPECT_EQ(a.query("ECHO a"), "a\n");
  EXPECT_EQ(b.query("ECHO b"), "b\n");
  stop_flag = 1;  // what a signal handler does
  thread.join();
  EXPECT_TRUE(a.wait_closed(5.0));
  EXPECT_TRUE(b.wait_closed(5.0));
  EXPECT_EQ(handler.connects, 2);
  EXPECT_EQ(handler.disconnects, 2);
  EXPECT_GT(handler.polls, 0);
  EXPECT_EQ(server.client_count(), 0u);

  // stop() is sticky: once called, run() returns at once.
  server.stop();
  server.run();
  EXPECT_THROW(a.query("ECHO x"), std::runtime_error);
}

TEST(LineServerAddress, NonLoopbackNeedsAllowRemote) {
  TestHandler handler;
  try {
    LineServer server(ListenAddress{"0.0.0.0", 0, false}, LineServerLimits{}, handler);
    FAIL() << "0.0.0.0 was accepted without allow_remote";
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--allow-remote"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("0.0.0.0:0"), std::string::npos) << e.what();
  }
  LineServer remote(ListenAddress{"0.0.0.0", 0, true}, LineServerLimits{}, handler);
  EXPECT_NE(remote.port(), 0);
  // All of 127.0.0.0/8 is loopback.
  LineServer loopback(ListenAddress{"127.0.0.2", 0, false}, LineServerLimits{}, handler);
  EXPECT_NE(loopback.port(), 0);
}

TEST(LineServerAddress, UnparsableAddressOrBadLimitsThrow) {
  TestHandler handler;
  for (const char* host : {"not-an-address", "127.1", "::1", ""}) {
    try {
      LineServer server(ListenAddress{host, 0, true}, LineServerLimits{}, handler);
      ADD_FAILURE() << "'" << host << "' was accepted";
    } catch (const core::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("'"s + host + "'"), std::string::npos) << e.what();
    }
  }
  LineServerLimits no_clients;
  no_clients.max_clients = 0;
  EXPECT_THROW(LineServer(ListenAddress{"127.0.0.1", 0}, no_clients, handler), core::InputError);
  LineServerLimits zero_idle;
  zero_idle.idle_timeout_s = 0.0;
  EXPECT_THROW(LineServer(ListenAddress{"127.0.0.1", 0}, zero_idle, handler), core::InputError);
}

TEST(LineServerAddress, PortInUseThrowsNamingThePort) {
  TestHandler handler;
  LineServer first(ListenAddress{"127.0.0.1", 0}, LineServerLimits{}, handler);
  const std::string port = std::to_string(first.port());
  try {
    LineServer second(ListenAddress{"127.0.0.1", first.port()}, LineServerLimits{}, handler);
    FAIL() << "a second server bound port " << port;
  } catch (const core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("127.0.0.1:" + port), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("in use"), std::string::npos) << e.what();
  }
}

TEST(GcsClient, SplitsAnswersAndReportsConnectionFailures) {
  EXPECT_EQ(GcsClient::split_answer("0 1 X=1.0 \n0 1 Y=2.0 \n0 1 Z=3.0\n"),
            (std::vector<std::string>{"0 1 X=1.0", "0 1 Y=2.0", "0 1 Z=3.0"}));
  EXPECT_EQ(GcsClient::split_answer("\n"), std::vector<std::string>{""});

  // A port with no listener: bind one, learn its number, close it.
  std::uint16_t free_port = 0;
  {
    TestHandler handler;
    LineServer probe(ListenAddress{"127.0.0.1", 0}, LineServerLimits{}, handler);
    free_port = probe.port();
  }
  try {
    GcsClient client("127.0.0.1", free_port, 2.0);
    FAIL() << "connected to a closed port";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("127.0.0.1:" + std::to_string(free_port)),
              std::string::npos)
        << e.what();
  }

  // A server that closes instead of answering: read_answer() throws, it does not hang.
  TestHandler handler;
  LineServerLimits limits;
  limits.idle_timeout_s = 0.2;
  ServerThread server(handler, limits);
  auto client = server.connect();
  client->send_raw("ECHO no end");  // no LF: never answered, then idle
  EXPECT_THROW(client->read_answer(), std::runtime_error);
}

// The GCS side of the same rule as Http.OutOfDescriptorsItPausesAcceptingAndServesTheClientsItHas:
// out of descriptors, accepting pauses 100 ms per failure (no spin), the connected client is
// still answered, and the waiting ones are served once descriptors are back.
TEST(LineServerLimits, OutOfDescriptorsItPausesAcceptingAndServesTheClientsItHas) {
  TestHandler handler;
  ServerThread st(handler);
  auto client = st.connect();
  ASSERT_EQ(client->query("ECHO before"), "before\n");
  piezoshift::testing::WaitingClients waiting(3, st.port());

  int connected = 0;
  int answered = 0;
  std::uint64_t failures = 0;
  double exhausted_s = 0.0;
  {
    const testing::DescriptorsExhausted exhausted;
    const auto t0 = std::chrono::steady_clock::now();
    connected = waiting.connect_all();  // the kernel completes these into the backlog
    while (std::chrono::steady_clock::now() - t0 < std::chrono::milliseconds(500)) {
      answered += client->query("ECHO during") == "during\n" ? 1 : 0;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    failures = st.server().stats().accept_failures;
    exhausted_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  EXPECT_EQ(connected, 3);
  EXPECT_GE(failures, 1u);
  EXPECT_LE(static_cast<double>(failures), exhausted_s / 0.1 + 2.0)
      << failures << " failed accepts in " << exhausted_s << " s";
  EXPECT_GE(answered, 1);
  for (int fd : waiting.fds()) {
    ASSERT_EQ(::send(fd, "ECHO back\n", 10, MSG_NOSIGNAL), 10);
    std::string answer;
    char buf[256];
    for (ssize_t n;
         answer.find('\n') == std::string::npos && (n = ::recv(fd, buf, sizeof buf, 0)) > 0;)
      answer.append(buf, static_cast<std::size_t>(n));
    EXPECT_EQ(answer, "back\n");
  }
}

}  // namespace
}  // namespace piezoshift::host
