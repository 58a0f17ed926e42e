#include "piezoshift/host/gcs_client.hpp"

#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include <fmt/format.h>

#include "piezoshift/core/wall_time.hpp"

namespace piezoshift::host {

namespace {

using Clock = std::chrono::steady_clock;

//! poll() timeout in ms for the time left until deadline; -1 (forever) for an infinite one.
int poll_ms_until(double timeout_s, Clock::time_point start) {
  if (std::isinf(timeout_s))
    return -1;
  const double left_s = timeout_s - core::seconds_since(start);
  return left_s <= 0.0 ? 0 : static_cast<int>(std::ceil(left_s * 1000.0));
}

std::string describe(double timeout_s) {
  return fmt::format("{:g} s", timeout_s);
}

}  // namespace

GcsClient::GcsClient(const std::string& host, std::uint16_t port, double timeout_s,
                     std::size_t max_answer_bytes)
    : where_(fmt::format("{}:{}", host, port)),
      timeout_s_(timeout_s),
      max_answer_bytes_(max_answer_bytes) {
  if (!(timeout_s > 0.0))
    throw std::runtime_error(
        fmt::format("GCS client for {}: the timeout must be > 0 s (+inf: none)", where_));

  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(port);
  if (const int rc = ::getaddrinfo(host.c_str(), service.c_str(), &hints, &found); rc != 0)
    throw std::runtime_error(
        fmt::format("GCS client: cannot resolve {}: {}", where_, ::gai_strerror(rc)));

  std::string last_error = "no address";
  for (const addrinfo* a = found; a != nullptr && fd_ < 0; a = a->ai_next) {
    int fd = ::socket(a->ai_family, a->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) {
      last_error = std::strerror(errno);
      continue;
    }
    // Non-blocking connect, so that an unreachable host fails after timeout_s, not minutes.
    int err = 0;
    if (::connect(fd, a->ai_addr, a->ai_addrlen) != 0) {
      err = errno;
      if (err == EINPROGRESS) {
        pollfd p{fd, POLLOUT, 0};
        const auto start = Clock::now();
        int rc = 0;
        while ((rc = ::poll(&p, 1, poll_ms_until(timeout_s, start))) < 0 && errno == EINTR) {
        }
        socklen_t len = sizeof err;
        if (rc == 0)
          err = ETIMEDOUT;
        else if (rc < 0)
          err = errno;
        else if (::getsockopt(fd, SOL_SOCKET, SO_ERROR, &err, &len) != 0)
          err = errno;
      }
    }
    if (err != 0) {
      last_error = err == ETIMEDOUT ? "no connection within " + describe(timeout_s)
                                    : std::string(std::strerror(err));
      ::close(fd);
      continue;
    }
    const int one = 1;  // commands are short: send them now
    ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    fd_ = fd;
  }
  ::freeaddrinfo(found);
  if (fd_ < 0)
    throw std::runtime_error(
        fmt::format("GCS client: cannot connect to {}: {}", where_, last_error));
}

GcsClient::~GcsClient() {
  close();
}

void GcsClient::close() noexcept {
  if (fd_ >= 0)
    ::close(fd_);
  fd_ = -1;
}

void GcsClient::require_open() const {
  if (fd_ < 0)
    throw std::runtime_error(fmt::format("GCS client for {}: the connection is closed", where_));
}

bool GcsClient::wait_for(short events, double timeout_s) {
  pollfd p{fd_, events, 0};
  const auto start = Clock::now();
  for (;;) {
    const int rc = ::poll(&p, 1, poll_ms_until(timeout_s, start));
    if (rc > 0)
      return true;  // ready, or an error that the following recv()/send() reports
    if (rc == 0)
      return false;
    if (errno != EINTR)
      throw std::runtime_error(
          fmt::format("GCS client for {}: poll: {}", where_, std::strerror(errno)));
  }
}

void GcsClient::send(std::string_view command) {
  std::string line(command);
  line += '\n';
  send_raw(line);
}

void GcsClient::send_raw(std::string_view bytes) {
  require_open();
  while (!bytes.empty()) {
    // MSG_NOSIGNAL: a server that has closed gives an exception, not SIGPIPE.
    const ssize_t n = ::send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL);
    if (n > 0) {
      bytes.remove_prefix(static_cast<std::size_t>(n));
    } else if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
      if (!wait_for(POLLOUT, timeout_s_))
        throw std::runtime_error(
            fmt::format("GCS client: {} took no data for {}", where_, describe(timeout_s_)));
    } else if (!(n < 0 && errno == EINTR)) {
      throw std::runtime_error(
          fmt::format("GCS client: sending to {} failed: {}", where_, std::strerror(errno)));
    }
  }
}

bool GcsClient::receive_some() {
  require_open();
  char chunk[64 * 1024];
  for (;;) {
    const ssize_t n = ::recv(fd_, chunk, sizeof chunk, 0);
    if (n > 0) {
      buffer_.append(chunk, static_cast<std::size_t>(n));
      return true;
    }
    if (n == 0)
      return false;
    if (errno == EINTR)
      continue;
    if (errno != EAGAIN && errno != EWOULDBLOCK)
      throw std::runtime_error(
          fmt::format("GCS client: receiving from {} failed: {}", where_, std::strerror(errno)));
    if (!wait_for(POLLIN, timeout_s_))
      throw std::runtime_error(fmt::format("GCS client: no answer from {} within {}{}", where_,
                                           describe(timeout_s_),
                                           buffer_.empty() ? "" : " (answer incomplete)"));
  }
}

std::string GcsClient::read_answer() {
  for (;;) {
    // scanned_ saves re-scanning a large answer on every chunk.
    for (std::size_t lf; (lf = buffer_.find('\n', scanned_)) != std::string::npos;) {
      if (lf >= max_answer_bytes_)
        break;  // refused below, whether or not it ends here
      if (lf == 0 || buffer_[lf - 1] != ' ') {
        std::string answer = buffer_.substr(0, lf + 1);
        buffer_.erase(0, lf + 1);
        scanned_ = 0;
        return answer;
      }
      scanned_ = lf + 1;
    }
    scanned_ = buffer_.size();
    if (scanned_ > max_answer_bytes_)
      throw std::runtime_error(fmt::format(
          "GCS client: an answer from {} exceeds {} bytes, the largest a GCS answer can be (a "
          "DRR? of 8 tables x 8192 points): not a GCS server, or a broken one",
          where_, max_answer_bytes_));
    if (!receive_some())
      throw std::runtime_error(fmt::format(
          "GCS client: {} closed the connection{}", where_,
          buffer_.empty() ? ""
                          : fmt::format(" in the middle of an answer ({} bytes)", buffer_.size())));
  }
}

std::vector<std::string> GcsClient::split_answer(std::string_view answer) {
  std::vector<std::string> lines;
  while (!answer.empty()) {
    const std::size_t lf = answer.find('\n');
    std::string_view line = answer.substr(0, lf);  // the whole rest when there is no LF
    answer.remove_prefix(lf == std::string_view::npos ? answer.size() : lf + 1);
    if (lf != std::string_view::npos && !answer.empty() && !line.empty() && line.back() == ' ')
      line.remove_suffix(1);  // the continuation space of a line that is not the last
    lines.emplace_back(line);
  }
  return lines;
}

std::vector<std::string> GcsClient::read_answer_lines() {
  return split_answer(read_answer());
}

std::string GcsClient::query(std::string_view command) {
  send(command);
  return read_answer();
}

std::vector<std::string> GcsClient::query_lines(std::string_view command) {
  send(command);
  return read_answer_lines();
}

bool GcsClient::wait_closed(double timeout_s) {
  if (fd_ < 0)
    return true;
  const auto start = Clock::now();
  char chunk[64 * 1024];
  for (;;) {
    const ssize_t n = ::recv(fd_, chunk, sizeof chunk, 0);
    if (n == 0)
      return true;
    if (n > 0 || errno == EINTR)
      continue;
    if (errno != EAGAIN && errno != EWOULDBLOCK)
      return true;  // ECONNRESET and the like: closed too
    const int ms = poll_ms_until(timeout_s, start);
    if (ms == 0)
      return false;
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, ms) < 0 && errno != EINTR)
      return false;
  }
}

}  // namespace piezoshift::host
