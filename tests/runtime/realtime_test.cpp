// runtime::keep_off_cpu: `serve` takes the loop's CPU out of its network threads' CPUs, so that
// no client's work competes with the loop for it. runtime::leave_loop_scheduling: a
// worker the loop's thread starts leaves the CPU it inherited (the fringe lock's fit).
#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>
#include <unistd.h>

#include <atomic>
#include <thread>

#include "piezoshift/runtime/realtime.hpp"

namespace piezoshift::runtime {
namespace {

int first_cpu(const cpu_set_t& set) {
  for (int c = 0; c < CPU_SETSIZE; ++c)
    if (CPU_ISSET(c, &set))
      return c;
  return -1;
}

TEST(KeepOffCpu, TheThreadLeavesThatCpuAndKeepsTheOthers) {
  cpu_set_t mine;
  ASSERT_EQ(::pthread_getaffinity_np(::pthread_self(), sizeof(mine), &mine), 0);
  const int first = first_cpu(mine);
  std::atomic<bool> stop{false};
  std::thread worker([&] {
    while (!stop.load())
      std::this_thread::yield();
  });
  const int cpus = CPU_COUNT(&mine);
  const bool moved = keep_off_cpu(worker, first);
  cpu_set_t now;
  ASSERT_EQ(::pthread_getaffinity_np(worker.native_handle(), sizeof(now), &now), 0);
  stop = true;
  worker.join();
  if (cpus == 1) {
    // Its one CPU: nothing to move to, left as it was.
    EXPECT_FALSE(moved);
    EXPECT_TRUE(CPU_ISSET(first, &now));
    return;
  }
  EXPECT_TRUE(moved);
  EXPECT_FALSE(CPU_ISSET(first, &now));
  EXPECT_EQ(CPU_COUNT(&now), cpus - 1);
  // Not a thread, or no such CPU: nothing done.
  std::thread none;
  EXPECT_FALSE(keep_off_cpu(none, first));
}

// A thread pinned to one CPU, as request_realtime() pins the loop's, starts a worker: the worker
// inherits that one CPU and leaves it for the others, on normal scheduling.
TEST(LeaveLoopScheduling, AWorkerTheLoopStartsLeavesItsCpuForTheOthers) {
  const long online = ::sysconf(_SC_NPROCESSORS_ONLN);
  cpu_set_t mine;
  ASSERT_EQ(::pthread_getaffinity_np(::pthread_self(), sizeof(mine), &mine), 0);
  const int first = first_cpu(mine);
  bool left = false;
  int policy = -1;
  cpu_set_t worker_cpus;
  CPU_ZERO(&worker_cpus);
  std::thread loop([&] {
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(first, &one);
    ASSERT_EQ(::pthread_setaffinity_np(::pthread_self(), sizeof(one), &one), 0);
    std::thread worker([&] {
      left = leave_loop_scheduling();
      sched_param p{};
      ::pthread_getschedparam(::pthread_self(), &policy, &p);
      ::pthread_getaffinity_np(::pthread_self(), sizeof(worker_cpus), &worker_cpus);
    });
    worker.join();
  });
  loop.join();
  EXPECT_TRUE(left);
  EXPECT_EQ(policy, SCHED_OTHER);
  if (online < 2) {  // the one CPU there is: it stays
    EXPECT_TRUE(CPU_ISSET(first, &worker_cpus));
    return;
  }
  EXPECT_FALSE(CPU_ISSET(first, &worker_cpus));
  EXPECT_EQ(CPU_COUNT(&worker_cpus), static_cast<int>(online) - 1);
}

}  // namespace
}  // namespace piezoshift::runtime
