#include "piezoshift/io/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <signal.h>

#include <cerrno>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <limits>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"

namespace piezoshift::io {

namespace {
[[noreturn]] void fail(const std::string& path, const char* what, int err) {
  throw core::InputError(
      fmt::format("{}: cannot replace the file ({}): {}", path, what, std::strerror(err)));
}

// Removes "<dir>/.<name>.tmp.<pid>" left by a writer of the same file that was killed (SIGKILL
// cannot be caught) and whose process is gone. A live PID's file is left alone: it may be another
// writer's, mid-write. Best effort: a name that does not parse or cannot be removed is skipped.
void remove_stale_temporaries(const std::filesystem::path& dir, const std::string& name) {
  const std::string prefix = fmt::format(".{}.tmp.", name);
  std::error_code ec;
  for (std::filesystem::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string entry = it->path().filename().string();
    if (entry.size() <= prefix.size() || entry.compare(0, prefix.size(), prefix) != 0)
      continue;
    const std::string digits = entry.substr(prefix.size());
    long long pid = 0;
    const auto [end_ptr, err] = std::from_chars(digits.data(), digits.data() + digits.size(), pid);
    if (err != std::errc() || end_ptr != digits.data() + digits.size() || pid <= 0 ||
        pid > std::numeric_limits<pid_t>::max())
      continue;
    if (::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH)
      ::unlink(it->path().c_str());
  }
}

// The temporary is created, never opened if it exists (O_EXCL) nor through a symlink
// (O_NOFOLLOW): a symlink planted at ".NAME.tmp.PID" made `calibrate --out` overwrite the file it
// pointed to. One already there (a file of an earlier process with this PID, or a planted link)
// is unlinked, which removes a link and not its target, and the create tried once more.
int create_temporary(const std::string& tmp) {
  constexpr int kFlags = O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC;
  int fd = ::open(tmp.c_str(), kFlags, 0644);
  if (fd < 0 && errno == EEXIST && ::unlink(tmp.c_str()) == 0)
    fd = ::open(tmp.c_str(), kFlags, 0644);
  return fd;
}
}  // namespace

void write_file_atomically(const std::string& path, std::string_view contents) {
  const std::filesystem::path target(path);
  const std::filesystem::path dir =
      target.has_parent_path() ? target.parent_path() : std::filesystem::path(".");
  const std::string tmp =
      (dir / fmt::format(".{}.tmp.{}", target.filename().string(), ::getpid())).string();
  remove_stale_temporaries(dir, target.filename().string());

  const int fd = create_temporary(tmp);
  if (fd < 0)
    fail(path, "create temporary file", errno);
  const char* p = contents.data();
  std::size_t left = contents.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0 && errno == EINTR)
      continue;
    if (n < 0) {
      const int err = errno;
      ::close(fd);
      ::unlink(tmp.c_str());
      fail(path, "write", err);
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    ::unlink(tmp.c_str());
    fail(path, "fsync", err);
  }
  if (::close(fd) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    fail(path, "close", err);
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(tmp.c_str());
    fail(path, "rename", err);
  }
  const int dfd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd >= 0) {  // best effort: some file systems refuse fsync on a directory
    ::fsync(dfd);
    ::close(dfd);
  }
}

}  // namespace piezoshift::io
