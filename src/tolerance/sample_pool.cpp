#include "piezoshift/tolerance/sample_pool.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include <fmt/core.h>

#include "piezoshift/core/wall_time.hpp"

namespace piezoshift::tolerance {

void run_pool(std::size_t count, unsigned jobs, const std::function<void(std::size_t)>& job,
              const PoolProgress& progress) {
  if (count == 0)
    return;
  if (jobs == 0)
    jobs = std::max(1u, std::thread::hardware_concurrency());
  jobs = static_cast<unsigned>(std::min<std::size_t>(jobs, count));
  const auto start = std::chrono::steady_clock::now();
  std::atomic<std::size_t> next{0};
  std::size_t done = 0;
  std::exception_ptr first_error;
  std::mutex mutex;  // done, first_error, the progress callback
  const auto worker = [&] {
    for (std::size_t i = next++; i < count; i = next++) {
      std::exception_ptr error;
      try {
        job(i);
      } catch (...) {
        error = std::current_exception();
      }
      std::lock_guard lock(mutex);
      if (error && !first_error)
        first_error = error;
      ++done;
      if (progress)
        progress(done, count, core::seconds_since(start));
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

PoolProgress progress_lines(std::string what) {
  auto last_s = std::make_shared<double>(0.0);
  return [what = std::move(what), last_s](std::size_t done, std::size_t total, double t) {
    if (done != total && t - *last_s < 1.0)
      return;
    *last_s = t;
    const double rate = t > 0.0 ? static_cast<double>(done) / t : 0.0;
    const double left = rate > 0.0 ? static_cast<double>(total - done) / rate : 0.0;
    fmt::print(stderr, "piezoshift: {}: {}/{} done, {:.2f}/s, {:.0f} s left\n", what, done, total,
               rate, left);
  };
}

}  // namespace piezoshift::tolerance
