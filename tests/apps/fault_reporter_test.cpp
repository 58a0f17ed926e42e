// The fault reporter's thread leaves the loop's CPU as `serve`'s network threads do:
// found by its name in /proc/self/task, its CPUs read from the kernel.
#include <gtest/gtest.h>
#include <sched.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "fault_report.hpp"

namespace piezoshift::app {
namespace {

// The CPUs of this process's thread named `name` ("Cpus_allowed_list" of its status), "" when
// no thread has that name.
std::string cpus_of_thread(const std::string& name) {
  for (const auto& task : std::filesystem::directory_iterator("/proc/self/task")) {
    std::string comm;
    std::getline(std::ifstream(task.path() / "comm"), comm);
    if (comm != name)
      continue;
    std::ifstream status(task.path() / "status");
    for (std::string line; std::getline(status, line);)
      if (line.rfind("Cpus_allowed_list:", 0) == 0)
        return line.substr(line.find_first_not_of(" \t", 18));
  }
  return "";
}

TEST(FaultReporter, KeepsOffTheLoopsCpu) {
  cpu_set_t mine;
  ASSERT_EQ(::sched_getaffinity(0, sizeof(mine), &mine), 0);
  int last = -1;
  for (int c = 0; c < CPU_SETSIZE; ++c)
    if (CPU_ISSET(c, &mine))
      last = c;
  runtime::LoopStatus status;
  FaultReporter reporter(status, nullptr);
  const std::string before = cpus_of_thread("fault-report");
  ASSERT_FALSE(before.empty()) << "no thread named fault-report";
  const bool moved = reporter.keep_off_cpu(last);
  const std::string after = cpus_of_thread("fault-report");
  if (CPU_COUNT(&mine) == 1) {
    EXPECT_FALSE(moved);  // nowhere to go: left as it was
    EXPECT_EQ(after, before);
    return;
  }
  EXPECT_TRUE(moved);
  EXPECT_NE(after, before);
  // "0-1" becomes "0": the last CPU (the loop's by default) is no longer in the list's end.
  EXPECT_FALSE(after.ends_with(std::to_string(last))) << after;
  reporter.stop();
  EXPECT_FALSE(reporter.keep_off_cpu(last));  // no thread any more
}

}  // namespace
}  // namespace piezoshift::app
