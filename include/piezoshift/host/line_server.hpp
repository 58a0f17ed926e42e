#pragma once
// A single-threaded, poll()-based TCP server for line-oriented protocols (PI GCS 2.0 in
// `piezoshift serve`, docs/gcs.md). It knows the framing only: a request is one line ending in
// LF; what a line means and what to answer is the LineHandler's business.
//
// One turn of run():
//   handler.on_poll()
//   poll(wake-up fd, listening socket, every client: POLLIN only while it has no unhandled input
//        and is not throttled, POLLOUT only while its output is pending)
//   for each client: recv() one chunk into its input; handle its complete lines, at most
//                    kLinesPerTurn and none once its queued output reaches
//                    output_high_water_bytes: split at LF -> handler.on_line() -> queue the
//                    answer (a byte for which handler.is_immediate() holds, where a line would
//                    start: handler.on_immediate() at once, no LF needed)
//                    send() queued output (MSG_NOSIGNAL: a vanished peer is an error, not SIGPIPE)
//   disconnect idle clients, slow readers, failed or finished connections ->
//   handler.on_disconnect()
//   accept() new connections (beyond max_clients: accepted and closed at once)
// Nothing blocks on one client, and no client's work delays another's by more than one answer:
// all sockets are non-blocking, each client has its own input and output queue, a turn handles a
// bounded number of each client's lines, and a client that does not read its answers is
// throttled (its further lines wait, in its own socket, until it reads) and, if it reads nothing
// for send_timeout_s, disconnected. Not real-time code (heap, exceptions); it talks to the loop
// through its handler.
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "piezoshift/host/tcp_listener.hpp"

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
};

//! Identifies one connection; unique and never reused during a server's life.
using ClientId = std::uint64_t;

//! What the protocol implements (the GCS interpreter). Called from the run() thread only.
//! An exception from a handler ends run() (all connections are closed first) and propagates.
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
};

//! Counters since construction.
struct LineServerStats {
  std::uint64_t accepted = 0;             //!< connections served (on_connect calls)
  std::uint64_t refused_max_clients = 0;  //!< closed at once: max_clients already connected
  //! output beyond max_pending_output_bytes, or none of it taken for send_timeout_s
  std::uint64_t disconnected_slow = 0;
  std::uint64_t disconnected_idle = 0;  //!< nothing received for idle_timeout_s
  std::uint64_t overlong_lines = 0;     //!< lines longer than max_line_bytes
  std::uint64_t bytes_in = 0;           //!< received from all clients
  std::uint64_t bytes_out = 0;          //!< sent (accepted by the kernel) to all clients
  //! accept() failed for lack of descriptors or memory; each pauses accepting for 100 ms
  std::uint64_t accept_failures = 0;
};

class LineServer {
 public:
  //! Lines (and single-character commands) of one client handled per turn at most: a client that
  //! sends many cheap commands at once delays the others' by at most this many.
  static constexpr std::size_t kLinesPerTurn = 32;

  //! Binds and listens (SO_REUSEADDR, non-blocking). Throws core::InputError naming host:port for
  //! an unparsable address, a non-loopback address without allow_remote, invalid limits, or a
  //! failed bind/listen (with the system's reason, e.g. "Address already in use").
  LineServer(const ListenAddress& address, const LineServerLimits& limits, LineHandler& handler);
  //! Closes all sockets (without handler calls: run() has already reported its disconnections).
  ~LineServer();
  LineServer(const LineServer&) = delete;
  LineServer& operator=(const LineServer&) = delete;

  //! The bound port (the kernel's choice when ListenAddress::port was 0).
  std::uint16_t port() const noexcept { return listener_->port(); }
  //! Connections currently served. Thread-safe.
  std::size_t client_count() const noexcept { return client_count_.load(); }

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
  using Clock = std::chrono::steady_clock;

  struct Client {
    int fd = -1;
    ClientId id = 0;
    std::string unread;        // received, not handled yet (at most one read chunk)
    std::string input;         // the partial line received so far (at most max_line_bytes + 1)
    bool discarding = false;   // inside an overlong line: drop bytes up to the next LF
    bool input_ended = false;  // EOF received: no more reading, close once output is sent
    std::string output;        // queued answers; output[output_sent..] still to send
    std::size_t output_sent = 0;
    Clock::time_point last_input;
    Clock::time_point last_output;  // output queued on an empty queue, or taken by the socket
    enum class Close { kNo, kNow, kSlow, kIdle } close = Close::kNo;
    std::size_t pending() const { return output.size() - output_sent; }
  };

  void accept_clients();
  void read_from(Client& client);
  //! Handles the client's complete lines in unread, within the turn's budget (see the top).
  void serve_lines(Client& client);
  bool throttled(const Client& client) const;
  bool wants_input(const Client& client) const;
  //! Marks for closing a client whose input has ended and whose lines and answers are done.
  void close_if_done(Client& client);
  void queue(Client& client, std::string&& answer);
  void flush(Client& client);
  void close_marked_clients();
  void close_all_clients();

  LineServerLimits limits_;
  LineHandler& handler_;
  std::unique_ptr<TcpListener> listener_;
  ClientId next_id_ = 1;
  std::vector<Client> clients_;
  std::vector<char> read_buffer_;  // one recv() chunk, shared by all clients
  std::atomic<std::size_t> client_count_{0};
  std::atomic<bool> stop_requested_{false};
  static_assert(std::atomic<bool>::is_always_lock_free, "stop() must be async-signal-safe");

  // Counters, atomic so that stats() may be read from any thread while run() serves.
  struct AtomicStats {
    std::atomic<std::uint64_t> accepted{0}, refused_max_clients{0}, disconnected_slow{0},
        disconnected_idle{0}, overlong_lines{0}, bytes_in{0}, bytes_out{0};
  } stats_;
};

}  // namespace piezoshift::host
