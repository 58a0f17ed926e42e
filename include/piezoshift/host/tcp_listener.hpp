#pragma once
// The listening end of the poll server (poll_server.hpp) that both network servers run on (the
// GCS line server, line_server.hpp, and the dashboard's HTTP server, http_server.hpp): an IPv4
// TCP socket, non-blocking, bound and listening, and an eventfd that wakes the server's poll()
// from any thread or a signal handler.
//
//   parse_ipv4_host(host)   "localhost" or a numeric IPv4 address; says whether it is loopback
//                           (127.0.0.0/8), so a server can refuse a remote bind before binding
//   TcpListener(host, port) socket, SO_REUSEADDR (a restarted server binds again while old
//                           connections sit in TIME_WAIT), bind, listen; port 0 takes a free port
//   poll_fd()               the socket for poll(), or -1 (which poll() skips) for 100 ms after an
//                           accept failed for lack of resources
//   accept_client()         one pending connection, non-blocking, TCP_NODELAY; -1 when none is
//                           pending or when accept() failed for lack of resources (EMFILE,
//                           ENFILE, ENOBUFS, ENOMEM): then the connection stays in the backlog,
//                           so the socket stays readable, and a server that polled it at once
//                           would spin; the pause lets it serve the clients it has meanwhile
//   wake()                  async-signal-safe: makes wake_fd() readable; errno is kept
//   drain_wake()            after poll() reports wake_fd() readable
//
// Errors name the server and the address: core::InputError for what the user chose (an address
// that is not IPv4, a port that cannot be bound), std::runtime_error for the system refusing a
// descriptor.
#include <netinet/in.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <string>

namespace piezoshift::host {

struct Ipv4Host {
  in_addr address{};
  std::string numeric;  //!< dotted quad ("localhost" becomes 127.0.0.1)
  bool loopback = false;
};

//! Closes fd when it is open and marks it closed (-1); the listener's and the clients' sockets.
void close_fd(int& fd) noexcept;

//! server and where ("TCP server", "127.0.0.1:50000") name the error's source.
Ipv4Host parse_ipv4_host(const std::string& host, const std::string& server,
                         const std::string& where);

class TcpListener {
 public:
  TcpListener(const Ipv4Host& host, std::uint16_t port, const std::string& server,
              const std::string& where);
  ~TcpListener();
  TcpListener(const TcpListener&) = delete;
  TcpListener& operator=(const TcpListener&) = delete;

  int fd() const noexcept { return listen_fd_; }
  int wake_fd() const noexcept { return wake_fd_; }
  std::uint16_t port() const noexcept { return port_; }

  //! After accept() failed for lack of resources, the listener is left alone this long.
  static constexpr std::chrono::milliseconds kAcceptPause{100};
  int poll_fd() const noexcept;
  int accept_client() noexcept;
  //! accept() failures for lack of resources so far (each starts a pause).
  std::uint64_t accept_failures() const noexcept {
    return accept_failures_.load(std::memory_order_relaxed);
  }

  void wake() const noexcept;
  void drain_wake() const noexcept;

 private:
  int listen_fd_ = -1;
  int wake_fd_ = -1;
  std::uint16_t port_ = 0;
  std::chrono::steady_clock::time_point paused_until_{};
  std::atomic<std::uint64_t> accept_failures_{0};  // read from other threads (stats)
};

}  // namespace piezoshift::host
