// The twin's cost: one control tick of the full three-leg twin (its default 20 physics steps per
// 1 ms), alone and with the paper's controller closed through the shipping loop (the simulated
// bench: sim backend, supervisor, ControlLoop on a simulated clock). The counter x_real_time is
// simulated seconds per wall-clock second (docs/performance.md).
#include <benchmark/benchmark.h>

#include "piezoshift/plant/twin.hpp"
#include "piezoshift/rig/bench.hpp"

namespace {

using piezoshift::control::Vec3;
using piezoshift::plant::Twin;
using piezoshift::plant::TwinParams;

void set_real_time_counter(benchmark::State& state, double period_s) {
  state.counters["x_real_time"] =
      benchmark::Counter(period_s, benchmark::Counter::kIsIterationInvariantRate);
}

// Open loop: a slow staircase on the DAQ outputs, so every tick moves the amplifiers, the
// hysteresis, the mechanics and the sensors.
void BM_TwinTickOpenLoop(benchmark::State& state) {
  TwinParams p;
  p.physics_rate_Hz = static_cast<double>(state.range(0));
  Twin twin({}, p, 1);
  long k = 0;
  for (auto _ : state) {
    const double v = 1.0 + 0.5 * static_cast<double>((k++ / 200) % 16);
    twin.write_ao(Vec3{v, v, v});
    twin.advance();
    benchmark::DoNotOptimize(twin.read_ai());
  }
  set_real_time_counter(state, twin.model().control_period_s);
}
BENCHMARK(BM_TwinTickOpenLoop)->Arg(20000)->Arg(40000)->Arg(100000);

// Closed loop: the paper's controller and the twin, one tick each, with Z_d stepping between
// 1 um and 10 um every 0.5 s (steps, settling and holding, as the experiments do).
void BM_TwinTickWithController(benchmark::State& state) {
  piezoshift::rig::Bench bench({}, {}, 1);
  long k = 0;
  for (auto _ : state) {
    const double zd = (k++ / 500) % 2 == 0 ? 1.0 : 10.0;
    bench.drive_points(Vec3{zd, zd, zd});
    bench.run(bench.sample_time_s());
    benchmark::DoNotOptimize(bench.last_cycle());
  }
  set_real_time_counter(state, bench.sample_time_s());
}
BENCHMARK(BM_TwinTickWithController);

// Building a twin (the model: identification, eigenproblem, discretization).
void BM_TwinConstruction(benchmark::State& state) {
  for (auto _ : state) {
    Twin twin({}, {}, 1);
    benchmark::DoNotOptimize(twin.read_ai());
  }
}
BENCHMARK(BM_TwinConstruction);

}  // namespace
