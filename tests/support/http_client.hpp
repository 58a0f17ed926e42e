#pragma once
// A minimal blocking HTTP client for tests over loopback: one raw request, the whole answer up
// to the server's close (every answer but an event stream closes), and an event-stream reader.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace piezoshift::testing {

class HttpConnection {
 public:
  HttpConnection(std::uint16_t port, const std::string& host = "127.0.0.1") {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in sa{};
    sa.sin_family = AF_INET;
    sa.sin_port = htons(port);
    ::inet_pton(AF_INET, host.c_str(), &sa.sin_addr);
    if (::connect(fd_, reinterpret_cast<const sockaddr*>(&sa), sizeof sa) != 0)
      throw std::runtime_error("connect to " + host + ":" + std::to_string(port) + " failed");
  }
  ~HttpConnection() { ::close(fd_); }
  HttpConnection(const HttpConnection&) = delete;
  HttpConnection& operator=(const HttpConnection&) = delete;

  void send(const std::string& bytes) {
    std::size_t sent = 0;
    while (sent < bytes.size()) {
      const ssize_t n = ::send(fd_, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
      if (n <= 0)
        return;  // the server may close early (413, 431): what it answered is still read
      sent += static_cast<std::size_t>(n);
    }
  }
  //! Reads what arrives within timeout_s; stops at EOF. Returns false on EOF.
  bool read_some(std::string& into, double timeout_s) {
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(timeout_s * 1000)) <= 0)
      return true;
    char buf[65536];
    const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
    if (n <= 0)
      return false;
    into.append(buf, static_cast<std::size_t>(n));
    return true;
  }
  //! Everything up to EOF, or what came within timeout_s.
  std::string read_all(double timeout_s = 5.0) {
    std::string out;
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (std::chrono::steady_clock::now() < end && read_some(out, 0.05)) {
    }
    return out;
  }
  int fd() const { return fd_; }

 private:
  int fd_ = -1;
};

//! One request, the whole answer.
inline std::string http_exchange(std::uint16_t port, const std::string& request,
                                 double timeout_s = 5.0) {
  HttpConnection c(port);
  c.send(request);
  return c.read_all(timeout_s);
}

//! The status code of an answer ("HTTP/1.1 401 ..." -> 401), 0 when there is none.
inline int http_status(const std::string& answer) {
  if (answer.rfind("HTTP/1.1 ", 0) != 0 || answer.size() < 12)
    return 0;
  return std::stoi(answer.substr(9, 3));
}

//! The body of an answer (after the blank line).
inline std::string http_body(const std::string& answer) {
  const std::size_t at = answer.find("\r\n\r\n");
  return at == std::string::npos ? std::string{} : answer.substr(at + 4);
}

}  // namespace piezoshift::testing
