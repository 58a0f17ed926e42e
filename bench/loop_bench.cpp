// The real-time loop against the twin on the real clock: period error distribution and overruns
// at 1 kHz (the paper's rate) and 10 kHz, the paper's gains (re-expressed for the period), a 6 um
// step. Measures; the overrun rule is lifted so that a bad stretch is counted, not turned into a
// stop. Figures go to docs/performance.md.
//
//   piezoshift_loop_bench [duration_s = 30] [--json]
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include <fmt/core.h>

#include "piezoshift/runtime/control_loop.hpp"
#include "piezoshift/runtime/realtime.hpp"
#include "piezoshift/runtime/sim_backend.hpp"

namespace {

using namespace piezoshift::runtime;

struct Row {
  double rate_Hz;
  std::uint64_t ticks;
  double p50, p99, p999, max;  // period error, us
  double lat_p99, lat_max;     // wake latency, us
  double comp_p50, comp_max;   // compute, us
  std::uint64_t overruns, max_run;
  bool fault;
};

Row bench(double rate_Hz, double duration_s) {
  SimOptions so;
  so.rate_Hz = rate_Hz;
  SimBackend sim(so);
  sim.configure();
  MonotonicClock clock;
  LoopConfig cfg;
  cfg.rate_Hz = rate_Hz;
  cfg.duration_s = duration_s;
  const piezoshift::control::SemiClosedLoopParams params;  // the paper's
  SafetyLimits limits;
  limits.max_consecutive_overruns = 1'000'000'000;
  ControlLoop loop(cfg, params, limits, sim, clock, SetpointProfile::step(6.0));
  sim.activate();
  const LoopResult r = loop.run();
  sim.deactivate();
  const LoopStats& s = loop.stats();
  const auto us = [](std::int64_t ns) { return static_cast<double>(ns) * 1e-3; };
  return Row{rate_Hz,
             r.ticks,
             us(s.period_error.percentile_ns(0.5)),
             us(s.period_error.percentile_ns(0.99)),
             us(s.period_error.percentile_ns(0.999)),
             us(s.period_error.max_ns()),
             us(s.wake_latency.percentile_ns(0.99)),
             us(s.wake_latency.max_ns()),
             us(s.compute.percentile_ns(0.5)),
             us(s.compute.max_ns()),
             s.overruns,
             s.max_consecutive_overruns,
             r.fault_detected};
}

}  // namespace

int main(int argc, char** argv) {
  double duration_s = 30.0;
  bool json = false;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--json") == 0)
      json = true;
    else
      duration_s = std::atof(argv[i]);
  }
  const RealtimeReport rt = request_realtime(RealtimeRequest{});
  for (const std::string& r : rt.refusals)
    fmt::print(stderr, "loop_bench: warning: {}; running on\n", r);
  const Row rows[] = {bench(1000.0, duration_s), bench(10000.0, duration_s)};
  if (json) {
    fmt::print("[\n");
    for (std::size_t i = 0; i < 2; ++i) {
      const Row& r = rows[i];
      fmt::print(
          "  {{\"rate_Hz\": {}, \"ticks\": {}, \"period_error_p50_us\": {:.1f}, "
          "\"period_error_p99_us\": {:.1f}, \"period_error_p999_us\": {:.1f}, "
          "\"period_error_max_us\": {:.1f}, \"wake_latency_p99_us\": {:.1f}, "
          "\"wake_latency_max_us\": {:.1f}, \"compute_time_p50_us\": {:.1f}, "
          "\"compute_time_max_us\": {:.1f}, \"overruns\": {}, \"max_consecutive_overruns\": {}, "
          "\"fault_detected\": {}}}{}\n",
          r.rate_Hz, r.ticks, r.p50, r.p99, r.p999, r.max, r.lat_p99, r.lat_max, r.comp_p50,
          r.comp_max, r.overruns, r.max_run, r.fault ? "true" : "false", i == 0 ? "," : "");
    }
    fmt::print("]\n");
    return 0;
  }
  fmt::print("loop bench: sim, {:.0f} s per rate, SCHED_FIFO {}, mlockall {}, CPU {}\n", duration_s,
             rt.fifo ? "yes" : "no", rt.memory_locked ? "yes" : "no", rt.cpu);
  fmt::print(
      "{:>8} {:>8} | period error (us): {:>6} {:>7} {:>7} {:>8} | wake p99/max (us) | "
      "compute p50/max (us) | overruns (longest)\n",
      "rate Hz", "ticks", "p50", "p99", "p99.9", "max");
  for (const Row& r : rows) {
    fmt::print(
        "{:>8.0f} {:>8} | {:>25.1f} {:>7.1f} {:>7.1f} {:>8.1f} | {:>7.1f} / {:>7.1f} | "
        "{:>8.1f} / {:>8.1f} | {} ({}){}\n",
        r.rate_Hz, r.ticks, r.p50, r.p99, r.p999, r.max, r.lat_p99, r.lat_max, r.comp_p50,
        r.comp_max, r.overruns, r.max_run, r.fault ? "  FAULT" : "");
  }
  return 0;
}
