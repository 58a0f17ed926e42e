// instrument::FitThread: the fringe lock's fit beside the loop's ticks.
#include "piezoshift/instrument/fit_thread.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <thread>

namespace piezoshift::instrument {
namespace {

// The job runs on another thread while the caller goes on (here: ticks, counted), and the
// caller sees it done only after it is.
TEST(FitThread, TheJobRunsBesideTheCallerWhoSeesItDoneOnlyAfterItIs) {
  FitThread fit;
  EXPECT_TRUE(fit.idle());
  std::atomic<bool> release{false};
  std::thread::id ran_on;
  int result = 0;
  fit.run([&] {
    ran_on = std::this_thread::get_id();
    while (!release.load())
      std::this_thread::yield();
    result = 42;
  });
  int ticks = 0;
  for (; ticks < 100; ++ticks)  // the caller's ticks go on while the job waits
    EXPECT_FALSE(fit.idle());
  release = true;
  while (!fit.idle())
    ++ticks;
  EXPECT_GE(ticks, 100);
  EXPECT_EQ(result, 42);
  EXPECT_NE(ran_on, std::this_thread::get_id());
  // In order, one at a time: run() waits for the job before.
  for (int k = 0; k < 50; ++k)
    fit.run([&, k] { result = k; });
  fit.wait();
  EXPECT_EQ(result, 49);
}

// A job's exception is the caller's, once; the thread takes the next job.
TEST(FitThread, AJobsExceptionReachesTheCallerOnce) {
  FitThread fit;
  fit.run([] { throw std::invalid_argument("no pose"); });
  EXPECT_THROW(fit.wait(), std::invalid_argument);
  EXPECT_TRUE(fit.idle());
  fit.run([] { throw std::runtime_error("lost"); });
  bool thrown = false;
  for (;;) {
    try {
      if (fit.idle())
        break;
    } catch (const std::runtime_error&) {
      thrown = true;
      break;
    }
  }
  EXPECT_TRUE(thrown);
  EXPECT_TRUE(fit.idle());
  int n = 0;
  fit.run([&] { n = 7; });
  fit.wait();
  EXPECT_EQ(n, 7);
}

}  // namespace
}  // namespace piezoshift::instrument
