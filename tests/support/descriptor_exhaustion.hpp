#pragma once
// Runs this process out of file descriptors for a scope, as a server meets it under load: the
// soft RLIMIT_NOFILE is lowered to the lowest free descriptor, so every descriptor below the
// limit is taken and the next accept(), socket() or open() fails with EMFILE. Descriptors already
// open stay usable (a connect() or read() on them needs none). The destructor restores the limit.
// Only for tests that own the whole process: other threads cannot open anything meanwhile.
#include <fcntl.h>
#include <sys/resource.h>
#include <unistd.h>

#include <stdexcept>

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

}  // namespace piezoshift::testing
