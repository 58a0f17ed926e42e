#pragma once
// A thread of its own for the work a frame brings that the loop's ticks cannot wait for: the
// fringe lock's fit (psi::fit_frame_pose, about 5 ms a 256 px frame; the reference, longer).
// The sequence's thread ticks the loop; on a real-time clock a 5 ms fit between two 1 ms ticks
// would make them late. Here it runs beside them while the loop holds the stage, on normal
// scheduling and off the loop's CPU (runtime::leave_loop_scheduling).
//
// One job at a time: the sequence gives a frame's fit and ticks until idle(); it touches what the
// job touches (the lock, the frame's record) only then. A job's exception is the sequence's,
// rethrown by idle() or wait().
#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

namespace piezoshift::instrument {

class FitThread {
 public:
  FitThread();
  ~FitThread();
  FitThread(const FitThread&) = delete;
  FitThread& operator=(const FitThread&) = delete;

  //! Runs job on the thread; waits first for the one before, if any (the sequence never gives
  //! two: it waits for idle() before its next move).
  void run(std::function<void()> job);
  //! No job running or waiting; rethrows the last job's exception, once.
  bool idle();
  //! Blocks until idle(); rethrows as idle() does.
  void wait();

 private:
  void serve();
  void rethrow();

  std::mutex m_;
  std::condition_variable cv_;
  std::function<void()> job_;
  bool busy_ = false;
  bool stop_ = false;
  std::exception_ptr error_;
  std::thread thread_;  // last: started when the rest exists
};

}  // namespace piezoshift::instrument
