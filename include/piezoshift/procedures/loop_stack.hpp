#pragma once
// The loop stack `run`, `serve` and `calibrate --daq` build one way (and `measure` next), from the
// bottom up:
//
//   backend   --daq: the twin ("sim", at the loop's rate) or a Comedi board ("comedi[:DEVICE]",
//             with --trigger-line its trigger output), configured here, so a device that cannot
//             be opened is named before anything runs
//   clock     real time (MonotonicClock), free-run (SimulatedClock: as fast as the CPU allows)
//             or paced (PacedClock: the guided calibration's twin, paced by its rig)
//   faults    --fault specs, injected between the loop and the twin (fault_injection.hpp)
//   logger    --log: the CSV logger the loop's telemetry ring feeds (csv_logger.hpp)
//
// The loop itself stays the command's (its LoopConfig, profile or host link differ); it talks to
// daq() on clock() and pushes its telemetry into telemetry().
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "piezoshift/config/project_config.hpp"
#include "piezoshift/runtime/csv_logger.hpp"
#include "piezoshift/runtime/daq_backend.hpp"
#include "piezoshift/runtime/fault_injection.hpp"
#include "piezoshift/runtime/loop_clock.hpp"
#include "piezoshift/runtime/paced_clock.hpp"
#include "piezoshift/runtime/sim_backend.hpp"

namespace piezoshift::procedures {

enum class StackClock : std::uint8_t { kRealTime, kFreeRun, kPaced };

struct LoopStackOptions {
  std::string daq = "sim";  //!< --daq: sim, comedi or comedi:DEVICE
  double rate_Hz = 1000.0;  //!< the loop's rate (checked: check_loop_rate)
  std::uint64_t seed = 1;   //!< the twin's
  std::string config_path;  //!< where the configuration came from ("" built in), for messages
  StackClock clock = StackClock::kRealTime;
  std::vector<std::string> faults;  //!< --fault specs (the twin only)
  std::string log;                  //!< --log CSV path ("" none)
  //! The log's thread reports each latched fault on stderr (false: the command has a
  //! FaultReporter, fault_report.hpp, which names its value and limit too)
  bool log_reports_faults = true;
  //! --trigger-line SUBDEVICE/CHANNEL: the Comedi board's trigger output ("" none; the twin's
  //! line is built in)
  std::string trigger_line;
};

class LoopStack {
 public:
  //! Builds and configures the stack. Throws core::InputError naming the option or device at fault.
  LoopStack(const LoopStackOptions& options, const config::ProjectConfig& config);
  ~LoopStack();
  LoopStack(const LoopStack&) = delete;
  LoopStack& operator=(const LoopStack&) = delete;

  //! What the loop talks to: the fault injector when there are faults, else the backend.
  runtime::DaqBackend& daq() { return injector_ ? *injector_ : *backend_; }
  //! The board or the twin ("sim", "comedi:/dev/comedi0").
  std::string name() const { return backend_->name(); }
  //! The twin when --daq sim, else null.
  runtime::SimBackend* sim() { return sim_; }
  runtime::LoopClock& clock() { return *clock_; }
  //! The paced clock when the stack was built with one, else null.
  runtime::PacedClock* paced() { return paced_; }
  //! The fault injector when --fault was given, else null.
  const runtime::FaultInjectingBackend* injector() const { return injector_.get(); }
  //! The logger's ring when --log was given, else null.
  runtime::SpscRing<runtime::TelemetryRecord>* telemetry() {
    return logger_ ? &logger_->ring() : nullptr;
  }
  //! The CSV logger when --log was given, else null.
  const runtime::CsvLogger* logger() const { return logger_.get(); }
  std::int64_t period_ns() const { return period_ns_; }

  //! Starts the logger's thread: call it before the real-time request, so that it stays a normal
  //! thread. No-op without --log.
  void start_logging();
  //! Drains the ring, syncs and closes the log. Idempotent; no-op without --log.
  void stop_logging();

 private:
  std::int64_t period_ns_;
  std::unique_ptr<runtime::DaqBackend> backend_;
  runtime::SimBackend* sim_ = nullptr;
  std::unique_ptr<runtime::LoopClock> clock_;
  runtime::PacedClock* paced_ = nullptr;
  std::unique_ptr<runtime::FaultInjectingBackend> injector_;
  std::unique_ptr<runtime::CsvLogger> logger_;
};

}  // namespace piezoshift::procedures
