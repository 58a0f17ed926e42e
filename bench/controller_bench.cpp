#include <benchmark/benchmark.h>

#include "piezoshift/control/semi_closed_loop.hpp"

namespace {

using piezoshift::control::SemiClosedLoopController;
using piezoshift::control::Vec3;

// One full controller tick (polynomial, matrix, three PIDs, scaling) with the paper's parameters.
void BM_ControllerTick(benchmark::State& state) {
  SemiClosedLoopController c;
  Vec3 sgs{1.0, 1.0, 1.0};
  for (auto _ : state) {
    const auto out = c.update(Vec3{5.0, 5.0, 5.0}, sgs);
    sgs[0] = 0.9 * out.dac_V[0];
    benchmark::DoNotOptimize(out);
  }
}
BENCHMARK(BM_ControllerTick);

}  // namespace
