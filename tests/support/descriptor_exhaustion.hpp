#pragma once
// Runs this process out of file descriptors for a scope, as a server meets it under load: the
// soft RLIMIT_NOFILE is lowered to the lowest free descriptor, so every descriptor below the
// limit is taken and the next accept(), socket() or open() fails with EMFILE. Descriptors already
// open stay usable (a connect() or read() on them needs none). The destructor restores the limit.
// Only for tests that own the whole process: other threads cannot open anything meanwhile.
#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <stdexcept>
#include <vector>

namespace piezoshift::testing {

class DescriptorsExhausted {
 public:
  DescriptorsExhausted() {
    if (::getrlimit(RLIMIT_NOFILE, &saved_) != 0)
      throw std::runtime_error("getrlimit(RLIMIT_NOFILE) failed");
    const int lowest_free = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
    if (lowest_free < 0)
      throw std::runtime_error("no descriptor free before the test took them");
    ::close(lowest_free);
    rlimit lowered = saved_;
    lowered.rlim_cur = static_cast<rlim_t>(lowest_free);
    if (::setrlimit(RLIMIT_NOFILE, &lowered) != 0)
      throw std::runtime_error("setrlimit(RLIMIT_NOFILE) failed");
  }
  ~DescriptorsExhausted() { ::setrlimit(RLIMIT_NOFILE, &saved_); }
  DescriptorsExhausted(const DescriptorsExhausted&) = delete;
  DescriptorsExhausted& operator=(const DescriptorsExhausted&) = delete;

 private:
  rlimit saved_{};
};

//! n TCP sockets made while descriptors are free, to connect to port on loopback while they are
//! not (connect() needs no new descriptor); reads time out after 5 s, against a hang.
class WaitingClients {
 public:
  WaitingClients(int n, std::uint16_t port) {
    const timeval receive_timeout{5, 0};
    for (int i = 0; i < n; ++i) {
      fds_.push_back(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0));
      ::setsockopt(fds_.back(), SOL_SOCKET, SO_RCVTIMEO, &receive_timeout, sizeof receive_timeout);
    }
    address_.sin_family = AF_INET;
    address_.sin_port = htons(port);
    ::inet_pton(AF_INET, "127.0.0.1", &address_.sin_addr);
  }
  ~WaitingClients() {
    for (int fd : fds_)
      ::close(fd);
  }
  WaitingClients(const WaitingClients&) = delete;
  WaitingClients& operator=(const WaitingClients&) = delete;

  //! Connects every socket; the number that connected.
  int connect_all() {
    int connected = 0;
    for (int fd : fds_)
      connected +=
          ::connect(fd, reinterpret_cast<const sockaddr*>(&address_), sizeof address_) == 0 ? 1 : 0;
    return connected;
  }
  const std::vector<int>& fds() const { return fds_; }

 private:
  std::vector<int> fds_;
  sockaddr_in address_{};
};

}  // namespace piezoshift::testing
