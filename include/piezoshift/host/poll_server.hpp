#pragma once
// The poll(2) server both network servers run on: the GCS line server (line_server.hpp) and the
// dashboard's HTTP server (http_server.hpp) are protocol layers (a PollProtocol) over it. It owns
// the sockets, the bounds and the fairness; the protocol owns framing and meaning.
//
// One round of run():
//   protocol.on_round()
//   poll(wake-up fd, listener (-1 during an accept pause, tcp_listener.hpp), every client: POLLIN
//        while protocol.wants_input(), POLLOUT while output is queued); no sleep while
//        protocol.has_work() holds for a client
//   for each client: recv() at most read_budget_bytes -> protocol.on_input() (EOF: on_end_of_
//                    input()); protocol.serve(); send() what is queued (MSG_NOSIGNAL)
//   evict idle clients (no byte received for idle_timeout_s while input is wanted) and slow ones
//   (none of their queue taken for send_timeout_s); close the marked ones -> on_disconnect()
//   accept() new connections: beyond max_clients, the client whose request (line, HTTP request)
//        has been incomplete longest, at least evict_incomplete_when_full_s since its first byte,
//        else the client idle longest (no byte received for the longest time, at least
//        evict_idle_when_full_s), its input wanted either way, is closed to make room (counted);
//        when there is none, protocol.refusal() is sent best effort to the newcomer and it is
//        closed (counted)
// Fairness: a round reads at most read_budget_bytes from each client and then serves every
// client, so a client that floods delays another's answer by at most two budgets of its bytes
// (the rest of the round in which the other's bytes arrive, and the round that reads them), not
// by all it sent. Output: each client has its own queue, bounded by max_pending_output_bytes;
// queue() beyond the bound sends at once, and a client whose socket still takes too little is
// evicted as slow while the others are served. Room: silent connections cannot lock the others
// out, nor can connections that trickle a byte at a time and never end a request; a client
// that sent something within evict_idle_when_full_s, its request complete, keeps its place. Memory
// per client: read_budget_bytes (the protocol's own buffers aside) + max_pending_output_bytes + one
// answer. Not real-time code (heap, exceptions).
#include <poll.h>

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "piezoshift/host/tcp_listener.hpp"

namespace piezoshift::host {

//! Identifies one connection; unique and never reused during a server's life.
using ClientId = std::uint64_t;

struct PollServerLimits {
  //! Connections served at once; one more is accepted, sent refusal() and closed.
  std::size_t max_clients = 8;
  //! Bytes read from one client per round at most (the fairness budget).
  std::size_t read_budget_bytes = 64 * 1024;
  //! A client's queued output beyond this (after trying to send it) evicts it as slow.
  std::size_t max_pending_output_bytes = std::size_t{16} << 20;
  //! Queued output none of which the socket takes for this long [s] evicts as slow; +inf: never.
  double send_timeout_s = 10.0;
  //! No byte received for this long [s] while input is wanted evicts as idle; +inf: never.
  double idle_timeout_s = 600.0;
  //! With max_clients connected, a new connection closes the client idle longest if it has been
  //! idle (no byte received, input wanted) at least this long [s]; 0: always, +inf: never.
  double evict_idle_when_full_s = 1.0;
  //! With max_clients connected, a new connection first closes the client whose request (a line,
  //! an HTTP request) has been incomplete longest, if its first byte came at least this long ago
  //! [s] (PollProtocol::incomplete_since): a client that trickles a byte at a time is never silent
  //! for evict_idle_when_full_s. +inf: never.
  double evict_incomplete_when_full_s = 2.0;
};

//! Counters since construction.
struct PollServerStats {
  std::uint64_t accepted = 0;             //!< connections served
  std::uint64_t refused_max_clients = 0;  //!< closed at once: max_clients already connected
  std::uint64_t evicted_slow = 0;         //!< queue beyond its bound, or not taken in time
  std::uint64_t evicted_idle = 0;         //!< nothing received for idle_timeout_s
  std::uint64_t evicted_for_room = 0;     //!< idle longest when the table was full
  std::uint64_t failed = 0;  //!< closed because a protocol call threw for it (std::bad_alloc)
  std::uint64_t failed_rounds = 0;  //!< on_round() threw (its work lost, the clients served)
  std::uint64_t rounds = 0;         //!< rounds of run() (a clock for the tests)
  std::uint64_t bytes_in = 0;       //!< received from all clients
  std::uint64_t bytes_out = 0;      //!< sent (taken by the kernel) to all clients
  //! accept() failed for lack of descriptors or memory; each pauses accepting for 100 ms
  std::uint64_t accept_failures = 0;
};

//! One connection as the server sees it. A protocol derives its per-connection state from it.
class PollClient {
 public:
  virtual ~PollClient() = default;
  ClientId id() const noexcept { return id_; }
  //! Queued bytes not yet taken by the socket.
  std::size_t pending() const noexcept { return output_.size() - output_sent_; }
  //! Marked for closing at the end of the round: no more input, serve() or output for it.
  bool closing() const noexcept { return close_ != Close::kNo; }
  //! The peer has shut down its sending side.
  bool input_ended() const noexcept { return input_ended_; }

 private:
  friend class PollServer;
  using Clock = std::chrono::steady_clock;
  int fd_ = -1;
  ClientId id_ = 0;
  std::string output_;  // output_[output_sent_..] still to send
  std::size_t output_sent_ = 0;
  bool input_ended_ = false;
  bool finishing_ = false;  // close once output_ is sent
  Clock::time_point last_input_;
  Clock::time_point last_output_;  // output queued on an empty queue, or taken by the socket
  enum class Close { kNo, kNow, kSlow, kIdle, kRoom, kFailed } close_ = Close::kNo;
};

class PollServer;

//! What a protocol implements. Called from the run() thread only. A std::exception from a call
//! for one client (on_connect, on_input, on_end_of_input, serve) closes that client alone
//! (counted in `failed`), one from on_round() loses that round's work (`failed_rounds`); any
//! other exception ends run() (every connection is closed first, with on_disconnect()) and
//! propagates.
class PollProtocol {
 public:
  virtual ~PollProtocol() = default;
  //! The state of a new connection (a class derived from PollClient).
  virtual std::unique_ptr<PollClient> make_client() { return std::make_unique<PollClient>(); }
  virtual void on_connect(PollClient&) {}
  //! Called once for every connection on_connect() saw, however it ended.
  virtual void on_disconnect(PollClient&) {}
  //! Sent, best effort, to a connection refused for max_clients before it is closed.
  virtual std::string refusal() { return {}; }
  //! Every round, before poll(): at least every poll interval.
  virtual void on_round() {}
  //! Whether to read from the client this round (false: its bytes wait in its socket).
  virtual bool wants_input(const PollClient&) const { return true; }
  //! When the first byte of the client's request under way (a line, an HTTP request) arrived;
  //! nullopt when none is under way. Makes the client a first choice to close for room once the
  //! request is incomplete for evict_incomplete_when_full_s.
  virtual std::optional<std::chrono::steady_clock::time_point> incomplete_since(
      const PollClient&) const {
    return std::nullopt;
  }
  //! Work left from earlier rounds (e.g. input beyond a per-round budget): poll() does not sleep.
  virtual bool has_work(const PollClient&) const { return false; }
  //! At most read_budget_bytes received.
  virtual void on_input(PollClient&, std::string_view bytes) = 0;
  //! EOF; the default closes the connection.
  virtual void on_end_of_input(PollClient& client);
  //! Every round for every client not closing, after its input was read.
  virtual void serve(PollClient&) {}

 protected:
  //! The server this protocol runs on; set by PollServer's constructor.
  PollServer& server() const { return *server_; }

 private:
  friend class PollServer;
  PollServer* server_ = nullptr;
};

class PollServer {
 public:
  using Clock = std::chrono::steady_clock;

  //! Binds and listens (tcp_listener.hpp). name and where ("TCP server", "127.0.0.1:50000") name
  //! the source of errors; invalid limits throw core::InputError.
  PollServer(const Ipv4Host& host, std::uint16_t port, const std::string& name,
             const std::string& where, const PollServerLimits& limits, PollProtocol& protocol);
  //! Closes all sockets (without protocol calls: run() has already reported its disconnections).
  ~PollServer();
  PollServer(const PollServer&) = delete;
  PollServer& operator=(const PollServer&) = delete;

  std::uint16_t port() const noexcept { return listener_.port(); }
  //! Connections currently served. Thread-safe.
  std::size_t client_count() const noexcept { return client_count_.load(); }
  //! Serves until stop() or *stop_flag != 0 (checked every round), then closes every connection
  //! (what its socket takes of its queue is sent first). stop() is sticky.
  void run(const std::atomic<int>* stop_flag, int poll_interval_ms);
  //! Thread-safe and async-signal-safe.
  void stop() noexcept;
  //! Thread-safe snapshot of the counters.
  PollServerStats stats() const;

  // For the protocol, from the run() thread:
  //! Appends to the client's queue (sent at the end of the round); beyond the bound, see the top.
  void queue(PollClient& client, std::string_view bytes);
  //! Sends now what the socket takes.
  void flush(PollClient& client);
  //! Closes once the queue is sent (at once when it is empty).
  void finish(PollClient& client);
  //! Closes at the end of the round; queued output is dropped.
  void close(PollClient& client) noexcept;
  void for_each_client(const std::function<void(PollClient&)>& visit);

 private:
  void serve_round(int poll_interval_ms);
  void accept_clients();
  //! With the table full: marks the client idle longest for closing if it may go; true if one was.
  bool make_room();
  void read_from(PollClient& client);
  void evict_stale_clients();
  void close_marked_clients();
  void close_all_clients();

  PollServerLimits limits_;
  PollProtocol& protocol_;
  std::string name_;
  TcpListener listener_;
  ClientId next_id_ = 1;
  std::vector<std::unique_ptr<PollClient>> clients_;
  std::vector<char> read_buffer_;  // one recv(), shared by all clients
  std::vector<pollfd> fds_;        // [0] wake-up, [1] listener, [2 + i] clients_[i]
  std::atomic<std::size_t> client_count_{0};
  std::atomic<bool> stop_requested_{false};
  static_assert(std::atomic<bool>::is_always_lock_free, "stop() must be async-signal-safe");
  // Atomic so that stats() may be read from any thread while run() serves.
  struct AtomicStats {
    std::atomic<std::uint64_t> accepted{0}, refused_max_clients{0}, evicted_slow{0},
        evicted_idle{0}, evicted_for_room{0}, failed{0}, failed_rounds{0}, rounds{0}, bytes_in{0},
        bytes_out{0};
  } stats_;
};

}  // namespace piezoshift::host
