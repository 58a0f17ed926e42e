#include "piezoshift/instrument/fit_thread.hpp"

#include <utility>

#include "piezoshift/runtime/realtime.hpp"

namespace piezoshift::instrument {

FitThread::FitThread() : thread_([this] { serve(); }) {}

FitThread::~FitThread() {
  {
    const std::lock_guard<std::mutex> lock(m_);
    stop_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

void FitThread::serve() {
  // Refused (a container): the kernel then schedules it as it inherited, which costs the loop
  // overruns only where it shares the loop's CPU.
  runtime::leave_loop_scheduling();
  std::unique_lock<std::mutex> lock(m_);
  for (;;) {
    cv_.wait(lock, [this] { return stop_ || busy_; });
    if (!busy_)
      return;
    std::function<void()> job = std::move(job_);
    lock.unlock();
    std::exception_ptr error;
    try {
      job();
    } catch (...) {
      error = std::current_exception();
    }
    lock.lock();
    error_ = error;
    busy_ = false;
    cv_.notify_all();
  }
}

void FitThread::run(std::function<void()> job) {
  wait();
  {
    const std::lock_guard<std::mutex> lock(m_);
    job_ = std::move(job);
    busy_ = true;
  }
  cv_.notify_all();
}

void FitThread::rethrow() {
  if (std::exception_ptr e = std::exchange(error_, nullptr))
    std::rethrow_exception(e);
}

bool FitThread::idle() {
  const std::lock_guard<std::mutex> lock(m_);
  if (busy_)
    return false;
  rethrow();
  return true;
}

void FitThread::wait() {
  std::unique_lock<std::mutex> lock(m_);
  cv_.wait(lock, [this] { return !busy_; });
  rethrow();
}

}  // namespace piezoshift::instrument
