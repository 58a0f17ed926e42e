// A diagnostic, not a test: a plant driven open loop by a 1 kHz staircase of commands
// (one per line in DIAG_SEQ_FILE, SGS-scaled um, the same on the three channels, the first held
// 1 s before), simulated with the DAQ at 10 kHz so the true plate is printed every 0.1 ms.
//   build/release/tests/calibration/open_loop_ring PLANT   (default|payload|...)
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "piezoshift/config/project_config.hpp"
#include "piezoshift/rig/bench.hpp"
#include "plant_by_name.hpp"

int main(int argc, char** argv) {
  using namespace piezoshift;
  const std::string name = argc > 1 ? argv[1] : "default";
  config::ProjectConfig config = testing::plant_by_name(name);
  config.twin.daq.sample_time_s = 1e-4;
  if (const char* p = std::getenv("DIAG_AMP_POWER_SCALE"))
    config.twin.amplifier.average_power_W *= std::strtod(p, nullptr);
  if (const char* p = std::getenv("DIAG_PHYSICS_HZ"))
    config.twin.physics_rate_Hz = std::strtod(p, nullptr);
  control::SemiClosedLoopParams c;
  c.sample_time_s = 1e-4;
  std::vector<double> seq;
  const char* seq_file = std::getenv("DIAG_SEQ_FILE");
  std::ifstream in(seq_file != nullptr ? seq_file : "");
  for (double v; in >> v;)
    seq.push_back(v);
  if (seq.empty()) {
    std::fprintf(stderr, "open_loop_ring: DIAG_SEQ_FILE must name a file of commands (um)\n");
    return 2;
  }
  rig::BenchOptions bo;
  if (const char* p = std::getenv("DIAG_SUPERVISOR_SLEW"))
    bo.limits.max_slew_V_per_s = std::strtod(p, nullptr);
  rig::Bench bench(config, c, 1, bo);
  const auto volts = [&](double u) {
    control::Vec3 v{};
    for (std::size_t i = 0; i < 3; ++i)
      v[i] = c.scaling[i].um_to_dac(u);
    return v;
  };
  bench.drive_open_loop(volts(seq.front()));
  bench.run(1.0);
  const double t0 = bench.time_s();
  const auto mean3 = [](const control::Vec3& v) { return (v[0] + v[1] + v[2]) / 3.0; };
  const double z0 = mean3(bench.twin().truth().points_um);
  const double tail_s =
      std::getenv("DIAG_TAIL_S") ? std::strtod(std::getenv("DIAG_TAIL_S"), nullptr) : 0.03;
  const auto print = [&](const rig::Bench& b) {
    std::printf("%.4f %.6f\n", 1e3 * (b.time_s() - t0), mean3(b.twin().truth().points_um) - z0);
  };
  for (double u : seq) {
    bench.drive_open_loop(volts(u));
    bench.run(1e-3, print);
  }
  bench.run(tail_s, print);
  return 0;
}
