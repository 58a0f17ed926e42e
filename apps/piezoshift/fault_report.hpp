#pragma once
// Faults as a user reads them: `run` and `serve` print each on stderr as it latches and list
// every one in their summaries (text and JSON), named by its rule, channel, time and the value
// that tripped it against its limit, with their unit. An `overruns` trip also names the worst
// lateness of its overruns and the machine's load (/proc/loadavg, read when it is reported): a
// late host is a busy machine more often than a slow loop.
//
// FaultReporter is the host side of it: a thread of its own polls the loop's status
// (loop_status.hpp) a few times a second and prints what has been published since; the loop
// itself never does I/O. Its thread is named "fault-report" and, once the loop is pinned, kept
// off the loop's CPU (keep_off_cpu) as `serve`'s network threads are.
#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "piezoshift/runtime/daq_backend.hpp"
#include "piezoshift/runtime/fault_list.hpp"
#include "piezoshift/runtime/loop_status.hpp"

namespace piezoshift::app {

//! /proc/loadavg's three load averages ("0.52 0.58 0.59"), or "unknown" when it cannot be read.
std::string load_average();

//! "value 10 V, limit 9.98 V"; for `overruns` "3 consecutive ticks overran (limit 3), the worst
//! ended 500.0 us after the next deadline" and, when `load` is not empty, "; load average <load>".
std::string fault_values(const runtime::LatchedFault& f, const std::string& load = {});

//! One line: "sgs-rail on channel 2 at t = 0.2000 s (tick 200): value 10 V, limit 9.98 V";
//! (fault_values after the colon).
std::string describe_fault(const runtime::LatchedFault& f, const std::string& load = {});

//! {"reason", "channel" (1..3 or null), "tick", "time_s", "value", "limit", "unit"}; `overruns`
//! adds "worst_lateness_us" and "load_average".
nlohmann::json fault_json(const runtime::LatchedFault& f, const std::string& load = {});

//! The kept faults, each as fault_json, loads[i] the load its report read (may be shorter).
nlohmann::json faults_json(const runtime::FaultList& faults,
                           const std::vector<std::string>& loads = {});

//! The text summary's fault lines ("fault 1  ...", one per kept fault, and how many more).
std::string faults_text(const runtime::FaultList& faults,
                        const std::vector<std::string>& loads = {});

//! The summaries' line for the device's own error text of its last failed transaction
//! ("device error   Timer expired (...)"), or "" when none failed.
std::string device_error_line(const runtime::DaqBackend& daq);

//! After deactivate(): when the device would not take 0 V on its outputs, says so on stderr (the
//! amplifier must be switched off by hand) and returns true; `program` prefixes the message.
bool report_unsafe_outputs(const runtime::DaqBackend& daq, const std::string& program);

class FaultReporter {
 public:
  //! Starts the thread; each newly published fault becomes one line on `out`.
  FaultReporter(const runtime::LoopStatus& status, std::FILE* out = stderr);
  ~FaultReporter();
  FaultReporter(const FaultReporter&) = delete;
  FaultReporter& operator=(const FaultReporter&) = delete;

  //! Prints what is left and joins the thread. Idempotent.
  void stop();
  //! Takes the loop's CPU out of the thread's CPUs (runtime::keep_off_cpu): a report read from
  //! /proc and printed must not cost the loop a deadline. False when nothing changed (no other
  //! CPU, refused, or stopped).
  bool keep_off_cpu(int cpu);
  //! The load average read when fault i was printed (after stop(): every kept fault's).
  std::vector<std::string> loads() const;

 private:
  void loop();
  void report_new();

  const runtime::LoopStatus& status_;
  std::FILE* out_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool done_ = false;
  std::uint32_t reported_ = 0;
  std::vector<std::string> loads_;
  std::thread thread_;
};

}  // namespace piezoshift::app
