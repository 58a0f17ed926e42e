#include "fault_report.hpp"

#include <pthread.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <fstream>

#include <fmt/format.h>

#include "piezoshift/runtime/realtime.hpp"

namespace piezoshift::app {

using runtime::FaultReason;
using runtime::LatchedFault;

std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string one, five, fifteen;
  if (!(in >> one >> five >> fifteen))
    return "unknown";
  return one + " " + five + " " + fifteen;
}

namespace {

// A value with its unit: "10 V", "3 ticks", "2" (a DAQ status code).
std::string with_unit(double value, FaultReason reason) {
  const char* unit = runtime::value_unit(reason);
  return *unit != '\0' ? fmt::format("{:.4g} {}", value, unit) : fmt::format("{:.4g}", value);
}

}  // namespace

std::string fault_values(const LatchedFault& f, const std::string& load) {
  const runtime::FaultRecord& r = f.fault;
  if (r.reason == FaultReason::kOverruns)  // the rule, its count against its limit, the cause
    return fmt::format(
        "{:.0f} consecutive ticks overran (limit {:.0f}), the worst ended {:.1f} us "
        "after the next deadline{}",
        r.value, r.limit, f.worst_lateness_s * 1e6,
        load.empty() ? std::string() : "; load average " + load);
  return fmt::format("value {}, limit {}", with_unit(r.value, r.reason),
                     with_unit(r.limit, r.reason));
}

std::string describe_fault(const LatchedFault& f, const std::string& load) {
  const runtime::FaultRecord& r = f.fault;
  return fmt::format("{}{} at t = {:.4f} s (tick {}): {}", runtime::to_string(r.reason),
                     r.channel >= 0 ? fmt::format(" on channel {}", r.channel + 1) : std::string(),
                     f.t_s, r.tick, fault_values(f, load));
}

nlohmann::json fault_json(const LatchedFault& f, const std::string& load) {
  const runtime::FaultRecord& r = f.fault;
  const auto number = [](double v) {
    return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(fmt::format("{}", v));
  };
  nlohmann::json j = {
      {"reason", runtime::to_string(r.reason)},
      {"channel", r.channel >= 0 ? nlohmann::json(r.channel + 1) : nlohmann::json(nullptr)},
      {"tick", r.tick},
      {"time_s", f.t_s},
      {"value", number(r.value)},
      {"limit", number(r.limit)},
      {"unit", runtime::value_unit(r.reason)}};
  if (r.reason == FaultReason::kOverruns) {
    j["worst_lateness_us"] = f.worst_lateness_s * 1e6;
    j["load_average"] = load.empty() ? nlohmann::json(nullptr) : nlohmann::json(load);
  }
  return j;
}

nlohmann::json faults_json(const runtime::FaultList& faults,
                           const std::vector<std::string>& loads) {
  nlohmann::json a = nlohmann::json::array();
  for (std::uint32_t i = 0; i < faults.kept(); ++i)
    a.push_back(fault_json(faults.entries[i], i < loads.size() ? loads[i] : std::string()));
  return a;
}

std::string faults_text(const runtime::FaultList& faults, const std::vector<std::string>& loads) {
  std::string text;
  for (std::uint32_t i = 0; i < faults.kept(); ++i)
    text += fmt::format("fault {:<8} {}\n", i + 1,
                        describe_fault(faults.entries[i], i < loads.size() ? loads[i] : ""));
  if (faults.count > faults.kept())
    text += fmt::format("faults         {} more not kept (the first {} are above)\n",
                        faults.count - faults.kept(), faults.kept());
  return text;
}

std::string device_error_line(const runtime::DaqBackend& daq) {
  const std::string e = daq.device_error();
  return e.empty() ? e : fmt::format("device error   {} (the last transaction that failed)\n", e);
}

bool report_unsafe_outputs(const runtime::DaqBackend& daq, const std::string& program) {
  const std::string unsafe = daq.safe_state_error();
  if (unsafe.empty())
    return false;
  fmt::print(stderr, "{}: error: {}; the outputs hold their last value: switch the amplifier off\n",
             program, unsafe);
  return true;
}

FaultReporter::FaultReporter(const runtime::LoopStatus& status, std::FILE* out)
    : status_(status), out_(out), thread_([this] { loop(); }) {
  ::pthread_setname_np(thread_.native_handle(), "fault-report");  // for top -H and the tests
}

FaultReporter::~FaultReporter() {
  stop();
}

void FaultReporter::stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (done_)
      return;
    done_ = true;
  }
  wake_.notify_one();
  thread_.join();
  std::lock_guard<std::mutex> lock(mutex_);
  report_new();  // a fault of the last ticks
}

bool FaultReporter::keep_off_cpu(int cpu) {
  return runtime::keep_off_cpu(thread_, cpu);
}

std::vector<std::string> FaultReporter::loads() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return loads_;
}

void FaultReporter::loop() {
  std::unique_lock<std::mutex> lock(mutex_);
  while (!wake_.wait_for(lock, std::chrono::milliseconds(50), [this] { return done_; }))
    report_new();
}

// Called with the mutex held.
void FaultReporter::report_new() {
  const std::uint32_t published = status_.faults_published.load(std::memory_order_acquire);
  if (published < reported_)  // the loop restarted
    reported_ = 0;
  for (; reported_ < published; ++reported_) {
    if (reported_ >= runtime::kMaxFaultsKept)
      continue;  // counted, not kept: the summary says how many
    const LatchedFault& f = status_.faults[reported_];
    const std::string load = f.fault.reason == FaultReason::kOverruns ? load_average() : "";
    loads_.push_back(load);
    if (out_ != nullptr) {
      // Over `run`'s live status line on a terminal, not after it.
      const runtime::FaultRecord& r = f.fault;
      fmt::print(out_,
                 "{}piezoshift: fault latched at tick {} (t = {:.4f} s): {}{}, {}; outputs "
                 "ramping to 0 V\n",
                 ::isatty(::fileno(out_)) ? "\r\033[K" : "", r.tick, f.t_s,
                 runtime::to_string(r.reason),
                 r.channel >= 0 ? fmt::format(" on channel {}", r.channel + 1) : std::string(),
                 fault_values(f, load));
      std::fflush(out_);
    }
  }
}

}  // namespace piezoshift::app
