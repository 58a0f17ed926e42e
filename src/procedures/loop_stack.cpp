#include "piezoshift/procedures/loop_stack.hpp"

#include <cmath>
#include <optional>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/procedures/loop_setup.hpp"
#include "piezoshift/procedures/work_begins.hpp"
#include "piezoshift/runtime/comedi_backend.hpp"

namespace piezoshift::procedures {

namespace {

bool is_comedi(const std::string& daq) {
  return daq == "comedi" || daq.rfind("comedi:", 0) == 0;
}

std::unique_ptr<runtime::LoopClock> make_clock(StackClock kind, runtime::PacedClock*& paced) {
  switch (kind) {
    case StackClock::kFreeRun:
      return std::make_unique<runtime::SimulatedClock>();
    case StackClock::kPaced: {
      auto c = std::make_unique<runtime::PacedClock>();
      paced = c.get();
      return c;
    }
    case StackClock::kRealTime:
      break;
  }
  return std::make_unique<runtime::MonotonicClock>();
}

}  // namespace

LoopStack::LoopStack(const LoopStackOptions& o, const config::ProjectConfig& config)
    : period_ns_(0) {
  check_loop_rate(o.rate_Hz);
  period_ns_ = std::llround(1e9 / o.rate_Hz);
  std::vector<runtime::FaultSpec> faults;
  for (const std::string& f : o.faults)
    faults.push_back(runtime::parse_fault_spec(f));
  const bool comedi = is_comedi(o.daq);
  if (!comedi && o.daq != "sim")
    throw core::InputError(fmt::format("--daq '{}': expected sim or comedi:/dev/comediN", o.daq));
  if (!comedi && !o.trigger_line.empty())
    throw core::InputError(
        "--trigger-line: a Comedi board's digital channel; the twin's trigger line is built in");
  std::optional<runtime::ComediOptions::DigitalLine> trigger_line;
  if (!o.trigger_line.empty())
    trigger_line = runtime::parse_digital_line(o.trigger_line, "--trigger-line");
  if (comedi && !faults.empty())
    throw core::InputError("--fault needs --daq sim (faults are injected into the twin)");
  if (comedi && o.clock == StackClock::kFreeRun)
    throw core::InputError("--free-run needs --daq sim (hardware runs in real time)");
  if (comedi && o.clock == StackClock::kPaced)
    throw core::InputError("a paced clock needs the twin (hardware runs in real time)");

  work_begins();  // the device or the twin, then the loop
  if (comedi) {
    runtime::ComediOptions co;
    if (o.daq.size() > 7)
      co.device = o.daq.substr(7);
    co.trigger_line = trigger_line;
    backend_ = std::make_unique<runtime::ComediBackend>(co);
  } else {
    runtime::SimOptions so;
    so.design = config.design;
    so.twin = config.twin;
    so.seed = o.seed;
    so.rate_Hz = o.rate_Hz;
    if (!o.config_path.empty())
      so.source = o.config_path;
    auto s = std::make_unique<runtime::SimBackend>(so);
    sim_ = s.get();
    backend_ = std::move(s);
  }
  backend_->configure();  // comedi: names the device it cannot open (exit 2)

  clock_ = make_clock(o.clock, paced_);
  if (!faults.empty())
    injector_ = std::make_unique<runtime::FaultInjectingBackend>(
        *backend_, *clock_, period_ns_, faults, runtime::FaultInjectionParams{}, sim_);
  if (!o.log.empty()) {
    runtime::CsvLoggerOptions lo;
    lo.path = o.log;
    lo.with_truth = sim_ != nullptr;
    if (!o.log_reports_faults)
      lo.events = nullptr;
    logger_ = std::make_unique<runtime::CsvLogger>(lo);
  }
}

LoopStack::~LoopStack() {
  stop_logging();
}

void LoopStack::start_logging() {
  if (logger_)
    logger_->start();
}

void LoopStack::stop_logging() {
  if (logger_)
    logger_->stop();
}

}  // namespace piezoshift::procedures
