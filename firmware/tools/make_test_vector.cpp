// Records the firmware's test vector on the host: the paper's controller (double) in closed loop
// with the digital twin at 1 kHz, the twin's AI samples kept as the 16-bit ADC codes the DAQ
// delivers. Writes the blob of piezoshift/firmware/test_vector.hpp.
//
//   make_test_vector OUT.bin [TICKS]
//
// The set-point programme (piecewise constant, floats exact in binary): a saturating move first
// (so clamping is exercised, then ~97 s without saturation for the drift check), the paper's
// linearity staircase, repeatability moves, tilted set-points, lambda/8 phase steps, a long hold.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/firmware/test_vector.hpp"
#include "piezoshift/plant/twin.hpp"

namespace {

using piezoshift::control::SemiClosedLoopController;
using piezoshift::control::Vec3;
using piezoshift::firmware::SetpointSegment;
using piezoshift::firmware::VectorHeader;

constexpr std::uint32_t kSeed = 1;

std::vector<SetpointSegment> programme(std::uint32_t ticks) {
  std::vector<SetpointSegment> s;
  std::uint32_t t = 0;
  auto hold = [&](float z1, float z2, float z3, std::uint32_t n) {
    s.push_back(SetpointSegment{t, {z1, z2, z3}});
    t += n;
  };
  hold(0.0F, 0.0F, 0.0F, 500);
  hold(20.0F, 20.0F, 20.0F, 1500);  // beyond the stroke: every PID at its 16 um limit
  hold(0.0F, 0.0F, 0.0F, 1000);
  for (int level = 0; level <= 11; ++level)  // linearity staircase, 1 um steps of 2 s
    hold(static_cast<float>(level), static_cast<float>(level), static_cast<float>(level), 2000);
  for (int move = 0; move < 30; ++move)  // repeatability: 5 um <-> 10 um
    hold(move % 2 == 0 ? 5.0F : 10.0F, move % 2 == 0 ? 5.0F : 10.0F, move % 2 == 0 ? 5.0F : 10.0F,
         1000);
  hold(4.0F, 6.0F, 5.0F, 4000);  // tilted plate: unequal Z_d exercises the whole matrix
  hold(8.0F, 7.5F, 9.0F, 4000);
  hold(2.5F, 3.25F, 1.75F, 4000);
  for (int step = 0; step < 32; ++step) {  // lambda/8 = 79 nm phase steps (5/64 um, exact)
    const float z = 5.0F + 0.078125F * static_cast<float>(step);
    hold(z, z, z, 500);
  }
  hold(6.0F, 6.0F, 6.0F, 1000);
  if (t < ticks)
    hold(7.0F, 7.0F, 7.0F, ticks - t);  // a long hold to the end: where a float integrator drifts
  while (!s.empty() && s.back().start_tick >= ticks)
    s.pop_back();
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || argc > 3) {
    std::fprintf(stderr, "usage: make_test_vector OUT.bin [TICKS]\n");
    return 2;
  }
  const std::uint32_t ticks =
      argc == 3 ? static_cast<std::uint32_t>(std::stoul(argv[2])) : std::uint32_t{120000};
  try {
    piezoshift::plant::Twin twin({}, {}, kSeed);
    SemiClosedLoopController controller;
    const auto segments = programme(ticks);
    const double lsb_V = 20.0 / 65536.0;  // the PCI-6229's +-10 V, 16 bit

    std::vector<std::int16_t> codes;
    codes.reserve(std::size_t{ticks} * 3);
    std::size_t seg = 0;
    Vec3 ai = twin.read_ai();
    for (std::uint32_t k = 0; k < ticks; ++k) {
      while (seg + 1 < segments.size() && segments[seg + 1].start_tick <= k)
        ++seg;
      const auto& z = segments[seg].zd_um;
      for (double v : ai) {
        const double code = std::nearbyint(v / lsb_V);
        if (!(std::fabs(code * lsb_V - v) < 1e-12) || code < -32768.0 || code > 32767.0)
          throw std::runtime_error("AI sample is not a 16-bit code: " + std::to_string(v));
        codes.push_back(static_cast<std::int16_t>(code));
      }
      const auto out = controller.update(Vec3{z[0], z[1], z[2]}, ai);
      // The plant's own steps, the same ones tests/mcu replays against both controllers.
      twin.write_ao(out.dac_V);
      twin.advance();
      ai = twin.read_ai();
    }

    VectorHeader h;
    h.ticks = ticks;
    h.segments = static_cast<std::uint32_t>(segments.size());
    h.ai_lsb_V = static_cast<float>(lsb_V);
    h.sample_time_s = static_cast<float>(twin.model().control_period_s);
    h.seed = kSeed;
    std::ofstream f(argv[1], std::ios::binary | std::ios::trunc);
    f.write(reinterpret_cast<const char*>(&h), sizeof h);
    f.write(reinterpret_cast<const char*>(segments.data()),
            static_cast<std::streamsize>(segments.size() * sizeof(SetpointSegment)));
    f.write(reinterpret_cast<const char*>(codes.data()),
            static_cast<std::streamsize>(codes.size() * sizeof(std::int16_t)));
    if (!f.flush())
      throw std::runtime_error(std::string("cannot write ") + argv[1]);
    std::printf("make_test_vector: %u ticks, %u set-point segments, %zu bytes -> %s\n", ticks,
                h.segments, piezoshift::firmware::vector_size(h), argv[1]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_test_vector: %s\n", e.what());
    return 1;
  }
  return 0;
}
