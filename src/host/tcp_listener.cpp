#include "piezoshift/host/tcp_listener.hpp"

#include <arpa/inet.h>
#include <netinet/tcp.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"

namespace piezoshift::host {

void close_fd(int& fd) noexcept {
  if (fd >= 0)
    ::close(fd);
  fd = -1;
}

Ipv4Host parse_ipv4_host(const std::string& host, const std::string& server,
                         const std::string& where) {
  Ipv4Host h;
  h.numeric = host == "localhost" ? "127.0.0.1" : host;
  if (::inet_pton(AF_INET, h.numeric.c_str(), &h.address) != 1)
    throw core::InputError(fmt::format(
        "{} on {}: '{}' is not a numeric IPv4 address (nor localhost)", server, where, host));
  h.loopback = (ntohl(h.address.s_addr) >> 24) == 127;
  return h;
}

TcpListener::TcpListener(const Ipv4Host& host, std::uint16_t port, const std::string& server,
                         const std::string& where) {
  try {
    wake_fd_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
    if (wake_fd_ < 0)
      throw std::runtime_error(
          fmt::format("{} on {}: eventfd: {}", server, where, std::strerror(errno)));
    listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (listen_fd_ < 0)
      throw std::runtime_error(
          fmt::format("{} on {}: socket: {}", server, where, std::strerror(errno)));
    const int one = 1;
    ::setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    sockaddr_in sa{};
    sa.sin_family = AF_INET;
    sa.sin_port = htons(port);
    sa.sin_addr = host.address;
    if (::bind(listen_fd_, reinterpret_cast<const sockaddr*>(&sa), sizeof sa) != 0)
      throw core::InputError(
          fmt::format("{} cannot bind {}: {}", server, where, std::strerror(errno)));
    if (::listen(listen_fd_, SOMAXCONN) != 0)
      throw core::InputError(
          fmt::format("{} cannot listen on {}: {}", server, where, std::strerror(errno)));
    socklen_t len = sizeof sa;
    if (::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&sa), &len) != 0)
      throw std::runtime_error(
          fmt::format("{} on {}: getsockname: {}", server, where, std::strerror(errno)));
    port_ = ntohs(sa.sin_port);
  } catch (...) {
    close_fd(listen_fd_);
    close_fd(wake_fd_);
    throw;
  }
}

TcpListener::~TcpListener() {
  close_fd(listen_fd_);
  close_fd(wake_fd_);
}

void TcpListener::wake() const noexcept {
  const int saved_errno = errno;  // a signal handler must leave errno as it found it
  const std::uint64_t one = 1;
  if (::write(wake_fd_, &one, sizeof one) < 0) {
    // EAGAIN: the counter is already non-zero, so poll() wakes anyway.
  }
  errno = saved_errno;
}

void TcpListener::drain_wake() const noexcept {
  std::uint64_t count = 0;
  if (::read(wake_fd_, &count, sizeof count) < 0) {
    // EAGAIN: already drained.
  }
}

int TcpListener::poll_fd() const noexcept {
  return std::chrono::steady_clock::now() >= paused_until_ ? listen_fd_ : -1;
}

int TcpListener::accept_client() noexcept {
  for (;;) {
    const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd >= 0) {
      // Answers are short and latency matters more than packet count.
      const int one = 1;
      ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
      return fd;
    }
    if (errno == EINTR || errno == ECONNABORTED)  // ECONNABORTED: that one left already
      continue;
    if (errno != EAGAIN && errno != EWOULDBLOCK) {
      paused_until_ = std::chrono::steady_clock::now() + kAcceptPause;
      accept_failures_.fetch_add(1, std::memory_order_relaxed);
    }
    return -1;
  }
}

}  // namespace piezoshift::host
