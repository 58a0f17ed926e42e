#pragma once
// Asking Linux for real-time treatment of the calling thread, once, at set-up:
//   mlockall(MCL_CURRENT | MCL_FUTURE)      no page faults on the loop's path
//   sched_setaffinity(cpu)                  one CPU, no migrations
//   sched_setscheduler(SCHED_FIFO, prio)    preempts every normal thread
//   touch stack_prefault_bytes of stack     so the locked stack pages exist before the loop
// Each request may be refused (no CAP_SYS_NICE / RLIMIT_RTPRIO / RLIMIT_MEMLOCK, a container):
// the report says which and why, the caller says so once and runs on.
#include <string>
#include <thread>
#include <vector>

namespace piezoshift::runtime {

struct RealtimeRequest {
  bool lock_memory = true;
  int cpu = -1;       //!< CPU to pin to; -1: the last online CPU; -2: do not pin
  int priority = 80;  //!< SCHED_FIFO priority (1..99)
  std::size_t stack_prefault_bytes = 256 * 1024;
};

struct RealtimeReport {
  bool memory_locked = false;
  bool fifo = false;
  int cpu = -1;                       //!< the CPU pinned to, -1 when not pinned
  std::vector<std::string> refusals;  //!< one line per refused request, with the reason
};

//! Set-up; never throws for a refusal (it is reported).
RealtimeReport request_realtime(const RealtimeRequest& request);

//! Takes `cpu` out of a normal thread's CPUs (the loop's, RealtimeReport::cpu), so that the
//! thread's work never competes with the loop for it, granted SCHED_FIFO or not. False (nothing
//! changed) when the thread has no other CPU or the kernel refuses.
bool keep_off_cpu(std::thread& thread, int cpu);

//! For a worker the loop's thread starts, called on the worker: it inherits the loop's
//! SCHED_FIFO and, when the loop is pinned, its one CPU, where its work would delay ticks. Back
//! to SCHED_OTHER, and off that CPU onto the others when there are any. False when the kernel
//! refused either (the worker then runs on as it is).
bool leave_loop_scheduling();

}  // namespace piezoshift::runtime
