#include "sample_pool.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include <fmt/core.h>

namespace piezoshift::app {
namespace {

// At most one progress line a second (and the last), so a log stays readable.
class Progress {
 public:
  Progress(std::size_t total, std::string what) : total_(total), what_(std::move(what)) {}
  void one_done() {
    std::lock_guard lock(mutex_);
    ++done_;
    const double t = std::chrono::duration<double>(clock::now() - start_).count();
    if (done_ != total_ && t - last_s_ < 1.0)
      return;
    last_s_ = t;
    const double rate = t > 0.0 ? static_cast<double>(done_) / t : 0.0;
    const double left = rate > 0.0 ? static_cast<double>(total_ - done_) / rate : 0.0;
    fmt::print(stderr, "piezoshift: {}: {}/{} done, {:.2f}/s, {:.0f} s left\n", what_, done_,
               total_, rate, left);
  }

 private:
  using clock = std::chrono::steady_clock;
  std::mutex mutex_;
  std::size_t total_, done_ = 0;
  std::string what_;
  clock::time_point start_ = clock::now();
  double last_s_ = 0.0;
};

}  // namespace

void run_pool(std::size_t count, unsigned jobs, const std::function<void(std::size_t)>& job,
              const std::string& what) {
  if (count == 0)
    return;
  if (jobs == 0)
    jobs = std::max(1u, std::thread::hardware_concurrency());
  jobs = static_cast<unsigned>(std::min<std::size_t>(jobs, count));
  Progress progress(count, what);
  std::atomic<std::size_t> next{0};
  std::exception_ptr first_error;
  std::mutex error_mutex;
  const auto worker = [&] {
    for (std::size_t i = next++; i < count; i = next++) {
      try {
        job(i);
      } catch (...) {
        std::lock_guard lock(error_mutex);
        if (!first_error)
          first_error = std::current_exception();
      }
      progress.one_done();
    }
  };
  std::vector<std::thread> threads;
  for (unsigned t = 1; t < jobs; ++t)
    threads.emplace_back(worker);
  worker();
  for (std::thread& t : threads)
    t.join();
  if (first_error)
    std::rethrow_exception(first_error);
}

}  // namespace piezoshift::app
