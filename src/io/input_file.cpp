#include "piezoshift/io/input_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"

namespace piezoshift::io {

namespace {

const char* kind_of(mode_t mode) {
  if (S_ISDIR(mode))
    return "a directory";
  if (S_ISCHR(mode) || S_ISBLK(mode))
    return "a device";
  if (S_ISFIFO(mode))
    return "a FIFO (pipe)";
  if (S_ISSOCK(mode))
    return "a socket";
  return "not a regular file";
}

// Closes the descriptor on every path out.
struct Fd {
  int fd;
  ~Fd() {
    if (fd >= 0)
      ::close(fd);
  }
};

}  // namespace

std::string read_input_file(const std::string& path, std::uintmax_t max_bytes) {
  // O_NONBLOCK: opening a FIFO without a writer must not wait; regular files ignore it.
  const Fd f{::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC)};
  if (f.fd < 0)
    throw core::InputError(fmt::format("{}: cannot open: {}", path, std::strerror(errno)));
  struct stat st {};
  if (::fstat(f.fd, &st) != 0)
    throw core::InputError(fmt::format("{}: cannot read: {}", path, std::strerror(errno)));
  if (!S_ISREG(st.st_mode))
    throw core::InputError(
        fmt::format("{}: is {}; expected a regular file", path, kind_of(st.st_mode)));
  const auto size = static_cast<std::uintmax_t>(st.st_size);
  if (size > max_bytes) {
    throw core::InputError(fmt::format(
        "{}: {} bytes is more than the limit of {} bytes for this file", path, size, max_bytes));
  }
  // One byte more than stat() said, so that the read which finds the end needs no reallocation
  // (growing the string would double it: 3 times the file's size at once).
  std::string data(static_cast<std::size_t>(size) + 1, '\0');
  std::size_t got = 0;
  for (;;) {
    if (got == data.size()) {
      if (data.size() >= max_bytes + 1)
        break;
      data.resize(static_cast<std::size_t>(std::min<std::uintmax_t>(max_bytes + 1, got + 4096)));
    }
    const ssize_t n = ::read(f.fd, data.data() + got, data.size() - got);
    if (n < 0 && errno == EINTR)
      continue;
    if (n < 0)
      throw core::InputError(fmt::format("{}: cannot read: {}", path, std::strerror(errno)));
    if (n == 0)
      break;
    got += static_cast<std::size_t>(n);
  }
  if (got > max_bytes) {
    throw core::InputError(fmt::format(
        "{}: grew past the limit of {} bytes for this file while read", path, max_bytes));
  }
  data.resize(got);
  return data;
}

}  // namespace piezoshift::io
