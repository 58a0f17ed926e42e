#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>

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

// One tick of the improved controller (kind = improved): the same feedforward, then per channel
// the rate limit and 3-tap shaper, the correction and the exact inverse of a 10-operator,
// 11-term hysteresis-creep model, as `calibrate --controller improved` identifies on the twin.
piezoshift::control::SemiClosedLoopParams improved_params() {
  using namespace piezoshift::control;
  SemiClosedLoopParams p;
  p.kind = ControllerKind::kImproved;
  for (auto& m : p.improved.model) {
    m.linear_weight = 0.51;
    m.operators = 10;
    m.creep_terms = 11;
    m.creep_gain = 0.0064;
    for (std::size_t j = 0; j < 10; ++j) {
      m.threshold_um[j] = 1.6 * (static_cast<double>(j) + 0.5);
      m.weight[j] = 0.04;
    }
    for (std::size_t k = 0; k < 11; ++k)
      m.creep_time_constant_s[k] = 0.003 * std::pow(10.0, 0.5 * static_cast<double>(k));
  }
  p.improved.shaper = design_mode_shaper(1419.0, 1e-3, 900.0);
  p.improved.correction_ki = 0.0314;
  return p;
}

// Alternating set-points (a 0.08 um phase step every 10 ticks) so that the inverse walks
// breakpoints and the shaper moves, the dearer path.
void BM_ImprovedControllerTick(benchmark::State& state) {
  piezoshift::control::SemiClosedLoopController c(improved_params());
  Vec3 sgs{3.0, 3.0, 3.0};
  std::uint64_t k = 0;
  for (auto _ : state) {
    const double z = (k++ / 10) % 2 == 0 ? 5.0 : 5.08;
    const auto out = c.update(Vec3{z, z, z}, sgs);
    sgs[0] = 0.51 * out.command_um[0] / 1.6;
    benchmark::DoNotOptimize(out);
  }
}
BENCHMARK(BM_ImprovedControllerTick);

}  // namespace
