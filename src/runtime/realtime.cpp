#include "piezoshift/runtime/realtime.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <fmt/core.h>

namespace piezoshift::runtime {

namespace {
// Touches the stack below the caller so its pages are mapped (and locked) before the loop runs.
__attribute__((noinline)) void prefault_stack(std::size_t bytes) {
  constexpr std::size_t kChunk = 4096;
  volatile unsigned char* probe = static_cast<volatile unsigned char*>(__builtin_alloca(bytes));
  for (std::size_t i = 0; i < bytes; i += kChunk)
    probe[i] = 0;
}
}  // namespace

RealtimeReport request_realtime(const RealtimeRequest& request) {
  RealtimeReport report;
  if (request.lock_memory) {
    if (::mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
      report.memory_locked = true;
      prefault_stack(request.stack_prefault_bytes);
    } else {
      report.refusals.push_back(fmt::format("mlockall refused: {}", std::strerror(errno)));
    }
  }
  if (request.cpu != -2) {
    int cpu = request.cpu;
    if (cpu == -1) {
      const long n = ::sysconf(_SC_NPROCESSORS_ONLN);
      cpu = n > 0 ? static_cast<int>(n - 1) : 0;
    }
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    if (::pthread_setaffinity_np(::pthread_self(), sizeof(set), &set) == 0) {
      report.cpu = cpu;
    } else {
      report.refusals.push_back(fmt::format("pinning to CPU {} refused", cpu));
    }
  }
  sched_param param{};
  param.sched_priority = request.priority;
  if (const int err = ::pthread_setschedparam(::pthread_self(), SCHED_FIFO, &param); err == 0) {
    report.fifo = true;
  } else {
    report.refusals.push_back(
        fmt::format("SCHED_FIFO priority {} refused: {}", request.priority, std::strerror(err)));
  }
  return report;
}

bool keep_off_cpu(std::thread& thread, int cpu) {
  if (cpu < 0 || cpu >= CPU_SETSIZE || !thread.joinable())
    return false;
  cpu_set_t set;
  CPU_ZERO(&set);
  if (::pthread_getaffinity_np(thread.native_handle(), sizeof(set), &set) != 0)
    return false;
  CPU_CLR(cpu, &set);
  if (CPU_COUNT(&set) == 0)
    return false;
  return ::pthread_setaffinity_np(thread.native_handle(), sizeof(set), &set) == 0;
}

bool leave_loop_scheduling() {
  sched_param normal{};
  bool ok = ::pthread_setschedparam(::pthread_self(), SCHED_OTHER, &normal) == 0;
  cpu_set_t mine;
  CPU_ZERO(&mine);
  if (::pthread_getaffinity_np(::pthread_self(), sizeof(mine), &mine) != 0)
    return false;
  const long online = ::sysconf(_SC_NPROCESSORS_ONLN);
  if (CPU_COUNT(&mine) != 1 || online < 2)
    return ok;  // not pinned (the loop was not, or the worker has only the one CPU there is)
  cpu_set_t others;
  CPU_ZERO(&others);
  for (int c = 0; c < online && c < CPU_SETSIZE; ++c)
    if (!CPU_ISSET(c, &mine))
      CPU_SET(c, &others);
  return ::pthread_setaffinity_np(::pthread_self(), sizeof(others), &others) == 0 && ok;
}

}  // namespace piezoshift::runtime
