#pragma once
// A single-threaded, poll()-based TCP server for line-oriented protocols (PI GCS 2.0 in
// `piezoshift serve`, docs/gcs.md). It knows the framing only: a request is one line ending in
// LF; what a line means and what to answer is the LineHandler's business.
//
// It runs on the shared poll server (poll_server.hpp: listener, accept back-off, client table,
// fair reads, bounded send queues, slow and idle eviction); what it adds per round and client:
//   handle the client's complete lines in the chunk read this round, at most kLinesPerTurn, none
//   once its queued output reaches output_high_water_bytes, none once its lines have taken
//   turn_budget_s of this round: split at LF ->
//   handler.on_line() -> queue the answer (a byte for which handler.is_immediate() holds, where a
//   line would start: handler.on_immediate() at once, no LF needed); an answer the handler makes
//   in parts (answer_pending()) takes a line's place in the turn for each part, and the client's
//   next line waits for its last part
// Nothing blocks on one client, and no client's work delays another's by more than one turn:
// a round reads at most kReadChunkBytes of each client and handles a bounded number of its
// lines (at most turn_budget_s of them, plus the one line that crosses it: the costliest GCS
// line is a DRR? of DataRecorder::kMaxAnswerBytes), and a client that does not read its answers
// is throttled (its further lines wait, in its own socket, until it reads) and, if it reads
// nothing for send_timeout_s, disconnected. With max_clients connected, a new client takes the
// place of the one whose line has been incomplete longest (at least evict_incomplete_when_full_s
// since its first byte), else of the one silent longest (at least evict_idle_when_full_s;
// poll_server.hpp).
// Memory per client: kReadChunkBytes unread + max_line_bytes + 1 of a partial line +
// max_pending_output_bytes queued + one answer (at most DataRecorder::kMaxAnswerBytes).
// Not real-time code (heap, exceptions); it talks to the loop through its handler.
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "piezoshift/host/poll_server.hpp"

namespace piezoshift::host {

//! Where the server listens.
struct ListenAddress {
  //! Numeric IPv4 address; "localhost" means 127.0.0.1.
  std::string host = "127.0.0.1";
  //! TCP port; 0 lets the kernel pick a free one (tests), see LineServer::port(). 50000 is the
  //! port PI controllers listen on for GCS over TCP/IP.
  std::uint16_t port = 50000;
  //! GCS has no authentication: an address outside 127.0.0.0/8 is refused unless this is set.
  bool allow_remote = false;
};

//! Resource bounds, so that no client can exhaust the server or starve the others.
struct LineServerLimits {
  //! Connections served at once; one more is accepted and closed at once (the peer sees EOF).
  std::size_t max_clients = 8;
  //! Longest line in bytes (without LF and trailing CR); a longer one gives on_overlong_line()
  //! once and the rest of it, up to the next LF, is discarded.
  std::size_t max_line_bytes = 4096;
  //! Output queued for one client beyond what its socket takes; an answer that would queue more
  //! (one larger than this) disconnects the client.
  std::size_t max_pending_output_bytes = std::size_t{16} << 20;
  //! Throttle: while this much output waits for a client, its further lines are not handled (nor
  //! read), so that answers nobody reads cost no work and other clients no time.
  std::size_t output_high_water_bytes = std::size_t{16} << 10;
  //! A client whose queued output its socket takes nothing of for this long [s] is disconnected.
  double send_timeout_s = 10.0;
  //! A client from which no byte arrives for this long [s] is disconnected; +inf: never.
  double idle_timeout_s = 600.0;
  //! With max_clients connected, a new connection takes the place of the client silent longest
  //! when it has been silent at least this long [s]; 0: always, +inf: never (the newcomer is
  //! refused).
  double evict_idle_when_full_s = 1.0;
  //! With max_clients connected, a new connection first takes the place of the client whose
  //! line has been incomplete longest (no LF yet), if its first byte came at least this long ago
  //! [s]; +inf: never. A client sending a byte every 0.9 s is never silent for 1 s.
  double evict_incomplete_when_full_s = 2.0;
  //! One client's lines handled in one round stop once they have taken this long [s] (the line
  //! that crosses it is finished): other clients are served in between.
  double turn_budget_s = 1e-3;
  //! A connection whose first line is HTTP's (http_line.hpp) is closed before anything of it is
  //! handled: a browser or curl pointed at the port does not have its request's body run.
  bool refuse_http = true;
};

//! What the protocol implements (the GCS interpreter). Called from the run() thread only.
//! A std::exception from a handler closes the client it was called for (the others are served,
//! LineServerStats::failed); from on_poll() it loses that poll (poll_server.hpp).
class LineHandler {
 public:
  virtual ~LineHandler() = default;
  virtual void on_connect(ClientId) {}
  //! Called once for every connection on_connect() saw, however it ended (including the end of
  //! run()).
  virtual void on_disconnect(ClientId) {}
  //! One complete line, without its LF and without one trailing CR, otherwise byte for byte as
  //! received (NUL, 0xFF, a lone CR included). Returns the bytes to send back (may be empty).
  virtual std::string on_line(ClientId, std::string_view line) = 0;
  //! A line longer than LineServerLimits::max_line_bytes; returns the bytes to send back.
  virtual std::string on_overlong_line(ClientId) { return {}; }
  //! True for a byte that is a whole command by itself when it starts a line (GCS's
  //! single-character commands, e.g. 0x05 for #5); such a byte is passed to on_immediate().
  virtual bool is_immediate(char) const { return false; }
  //! One single-character command; returns the bytes to send back.
  virtual std::string on_immediate(ClientId, char) { return {}; }
  //! Every turn of the loop, before input is handled: at least every poll interval.
  virtual void on_poll() {}
  //! True while the answer to the client's last line is not whole (a long DRR?): the server
  //! asks for the rest with more_answer(), a part per line of a turn's budget, before it hands
  //! the client's next line to on_line(), so other clients are served between the parts.
  virtual bool answer_pending(ClientId) const { return false; }
  //! The next part of the pending answer.
  virtual std::string more_answer(ClientId) { return {}; }
};

//! Counters since construction.
struct LineServerStats {
  std::uint64_t accepted = 0;             //!< connections served (on_connect calls)
  std::uint64_t refused_max_clients = 0;  //!< closed at once: max_clients already connected
  //! output beyond max_pending_output_bytes, or none of it taken for send_timeout_s
  std::uint64_t disconnected_slow = 0;
  std::uint64_t disconnected_idle = 0;  //!< nothing received for idle_timeout_s
  std::uint64_t evicted_for_room = 0;   //!< silent longest when a new client found the table full
  std::uint64_t rounds = 0;             //!< poll rounds served (a clock for the tests)
  std::uint64_t overlong_lines = 0;     //!< lines longer than max_line_bytes
  std::uint64_t refused_http = 0;       //!< closed: the first line was HTTP's (refuse_http)
  std::uint64_t failed = 0;             //!< closed: the handler threw for it
  std::uint64_t bytes_in = 0;           //!< received from all clients
  std::uint64_t bytes_out = 0;          //!< sent (accepted by the kernel) to all clients
  //! accept() failed for lack of descriptors or memory; each pauses accepting for 100 ms
  std::uint64_t accept_failures = 0;
};

class LineServer : private PollProtocol {
 public:
  //! Lines (and single-character commands) of one client handled per turn at most: a client that
  //! sends many cheap commands at once delays the others' by at most this many.
  static constexpr std::size_t kLinesPerTurn = 32;
  //! Bytes read from one client per round at most (PollServerLimits::read_budget_bytes).
  static constexpr std::size_t kReadChunkBytes = 64 * 1024;

  //! Binds and listens (SO_REUSEADDR, non-blocking). Throws core::InputError naming host:port for
  //! an unparsable address, a non-loopback address without allow_remote, invalid limits, or a
  //! failed bind/listen (with the system's reason, e.g. "Address already in use").
  LineServer(const ListenAddress& address, const LineServerLimits& limits, LineHandler& handler);
  //! Closes all sockets (without handler calls: run() has already reported its disconnections).
  ~LineServer() override;
  LineServer(const LineServer&) = delete;
  LineServer& operator=(const LineServer&) = delete;

  //! The bound port (the kernel's choice when ListenAddress::port was 0).
  std::uint16_t port() const noexcept { return core_->port(); }
  //! Connections currently served. Thread-safe.
  std::size_t client_count() const noexcept { return core_->client_count(); }

  //! Serves until stop() is called or *stop_flag != 0 (checked every turn, i.e. at least every
  //! poll_interval_ms; for signal handlers), then disconnects every client and returns. stop() is
  //! sticky: once called, run() returns at once.
  void run(const std::atomic<int>* stop_flag = nullptr, int poll_interval_ms = 2);
  //! Makes run() return. Thread-safe and async-signal-safe (an atomic store and a write() to an
  //! eventfd that wakes poll()).
  void stop() noexcept;
  //! Thread-safe snapshot of the counters.
  LineServerStats stats() const;

 private:
  struct Client;
  //! The connection as make_client() made it.
  static Client& client(PollClient& c) noexcept;
  static const Client& client(const PollClient& c) noexcept;
  std::unique_ptr<PollClient> make_client() override;
  void on_connect(PollClient& client) override;
  void on_disconnect(PollClient& client) override;
  void on_round() override { handler_.on_poll(); }
  bool wants_input(const PollClient& client) const override;
  bool has_work(const PollClient& client) const override;
  std::optional<std::chrono::steady_clock::time_point> incomplete_since(
      const PollClient& client) const override;
  void on_input(PollClient& client, std::string_view bytes) override;
  void on_end_of_input(PollClient& client) override;
  //! Handles the client's complete lines in unread, within the round's budget (see the top).
  void serve(PollClient& client) override;
  bool throttled(const PollClient& client) const;
  //! Closes, once its answers are sent, a client whose input has ended and whose lines are done.
  void finish_if_done(Client& client);

  LineServerLimits limits_;
  LineHandler& handler_;
  std::unique_ptr<PollServer> core_;
  std::atomic<std::uint64_t> overlong_lines_{0};
  std::atomic<std::uint64_t> refused_http_{0};
};

}  // namespace piezoshift::host
