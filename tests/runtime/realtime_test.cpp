// runtime::keep_off_cpu: `serve` takes the loop's CPU out of its network threads' CPUs, so that
// no client's work competes with the loop for it (issue 27).
#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>

#include <atomic>
#include <thread>

#include "piezoshift/runtime/realtime.hpp"

namespace piezoshift::runtime {
namespace {

TEST(KeepOffCpu, TheThreadLeavesThatCpuAndKeepsTheOthers) {
  cpu_set_t mine;
  ASSERT_EQ(::pthread_getaffinity_np(::pthread_self(), sizeof(mine), &mine), 0);
  int first = -1;
  for (int c = 0; c < CPU_SETSIZE && first < 0; ++c)
    if (CPU_ISSET(c, &mine))
      first = c;
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

}  // namespace
}  // namespace piezoshift::runtime
