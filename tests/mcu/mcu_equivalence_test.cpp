// The float controller on the Cortex-M4F firmware (QEMU netduinoplus2) against the host, over the
// recorded test vector (docs/mcu.md). The firmware runs under qemu-system-arm -icount shift=0 and
// writes every tick's outputs; the host replays the same inputs through the same controller
// template, in float and in double, and compares every tick. Paths come from the build:
// PIEZOSHIFT_QEMU, PIEZOSHIFT_FIRMWARE_ELF, PIEZOSHIFT_TEST_VECTOR.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/firmware/test_vector.hpp"
#include "piezoshift/plant/twin.hpp"

namespace piezoshift::firmware {
namespace {

using control::BasicSemiClosedLoopController;
using control::SemiClosedLoopController;
using control::SemiClosedLoopParams;
using control::Vec3;
using FloatController = BasicSemiClosedLoopController<float>;

std::vector<char> read_all(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

struct TestVector {
  VectorHeader header;
  std::vector<SetpointSegment> segments;
  std::vector<std::int16_t> codes;

  //! Z_d of tick k; seg carries the search from one tick to the next.
  const float* zd_um(std::uint32_t k, std::size_t& seg) const {
    while (seg + 1 < segments.size() && segments[seg + 1].start_tick <= k)
      ++seg;
    return segments[seg].zd_um;
  }
};

const TestVector& test_vector() {
  static const TestVector v = [] {
    TestVector t;
    const auto bytes = read_all(PIEZOSHIFT_TEST_VECTOR);
    if (bytes.size() < sizeof t.header)
      throw std::runtime_error("cannot read " PIEZOSHIFT_TEST_VECTOR);
    std::memcpy(&t.header, bytes.data(), sizeof t.header);
    if (t.header.magic != kVectorMagic || bytes.size() != vector_size(t.header))
      throw std::runtime_error("bad test vector " PIEZOSHIFT_TEST_VECTOR);
    t.segments.resize(t.header.segments);
    std::memcpy(t.segments.data(), bytes.data() + segments_offset(),
                t.segments.size() * sizeof(SetpointSegment));
    t.codes.resize(std::size_t{t.header.ticks} * 3);
    std::memcpy(t.codes.data(), bytes.data() + codes_offset(t.header),
                t.codes.size() * sizeof(std::int16_t));
    return t;
  }();
  return v;
}

struct FirmwareRun {
  std::vector<TickRecord> records;
  RunStats stats;
  double qemu_wall_s = 0.0;
};

// Runs the firmware under QEMU once for the whole executable (about 2 s).
const FirmwareRun& firmware_run() {
  static const FirmwareRun run = [] {
    FirmwareRun r;
    const std::uint32_t n = test_vector().header.ticks;
    const auto dir = std::filesystem::temp_directory_path() /
                     ("piezoshift_mcu_" +
                      std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
    std::filesystem::create_directories(dir);
    const auto out = dir / "outputs.bin";
    const std::string cmd = std::string("timeout 600 ") + PIEZOSHIFT_QEMU +
                            " -M netduinoplus2 -display none -monitor none -serial null"
                            " -icount shift=0 -kernel " PIEZOSHIFT_FIRMWARE_ELF
                            " -semihosting-config enable=on,target=native,"
                            "arg=piezoshift_firmware,arg=" +
                            out.string();
    std::fflush(stdout);
    const auto t0 = std::chrono::steady_clock::now();
    const int status = std::system(cmd.c_str());
    r.qemu_wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const auto bytes = read_all(out);
    std::filesystem::remove_all(dir);
    if (status != 0)
      throw std::runtime_error("firmware under QEMU failed (status " + std::to_string(status) +
                               "): " + cmd);
    if (bytes.size() != n * sizeof(TickRecord) + sizeof(RunStats))
      throw std::runtime_error("firmware wrote " + std::to_string(bytes.size()) + " bytes");
    r.records.resize(n);
    std::memcpy(r.records.data(), bytes.data(), n * sizeof(TickRecord));
    std::memcpy(&r.stats, bytes.data() + n * sizeof(TickRecord), sizeof r.stats);
    std::printf("mcu: firmware ran %u ticks (%.0f s at %.0f Hz) under QEMU in %.2f s wall\n", n,
                n * double{test_vector().header.sample_time_s},
                1.0 / double{test_vector().header.sample_time_s}, r.qemu_wall_s);
    return r;
  }();
  return run;
}

struct Comparison {
  double max_dac_V = 0.0;
  double max_command_um = 0.0;
  std::uint32_t max_at_tick = 0;
  std::uint32_t mask_mismatches = 0;
  std::uint32_t saturated_ticks = 0;
  std::uint32_t last_saturated_tick = 0;
  double max_command_um_next_10k = 0.0;  //!< over the 10 000 ticks after the last saturated one
  double max_command_um_last_10k = 0.0;  //!< over the last 10 000 ticks
};

// A host controller (the double one, or the same template in float) on the vector's inputs,
// against the firmware's outputs, every tick.
template <class Controller>
Comparison compare(const FirmwareRun& run, Controller c) {
  using T = typename Controller::Vec::value_type;
  const TestVector& v = test_vector();
  const std::uint32_t n = v.header.ticks;
  Comparison cmp;
  std::vector<double> diff_um(n);
  std::size_t seg = 0;
  for (std::uint32_t k = 0; k < n; ++k) {
    const float* z = v.zd_um(k, seg);
    typename Controller::Vec sgs{};
    for (std::size_t i = 0; i < 3; ++i)
      sgs[i] = static_cast<T>(v.codes[3 * k + i]) * static_cast<T>(v.header.ai_lsb_V);
    const auto out = c.update(typename Controller::Vec{z[0], z[1], z[2]}, sgs);
    const TickRecord& r = run.records[k];
    for (std::size_t i = 0; i < 3; ++i) {
      cmp.max_dac_V = std::max(cmp.max_dac_V, std::fabs(double{r.dac_V[i]} - double{out.dac_V[i]}));
      diff_um[k] =
          std::max(diff_um[k], std::fabs(double{r.command_um[i]} - double{out.command_um[i]}));
    }
    if (diff_um[k] > cmp.max_command_um) {
      cmp.max_command_um = diff_um[k];
      cmp.max_at_tick = k;
    }
    if (r.saturated_mask != out.saturated_mask)
      ++cmp.mask_mismatches;
    if (out.saturated_mask != 0) {
      ++cmp.saturated_ticks;
      cmp.last_saturated_tick = k;
    }
  }
  for (std::uint32_t k = cmp.last_saturated_tick + 1;
       k < std::min(n, cmp.last_saturated_tick + 10001); ++k)
    cmp.max_command_um_next_10k = std::max(cmp.max_command_um_next_10k, diff_um[k]);
  for (std::uint32_t k = n > 10000 ? n - 10000 : 0; k < n; ++k)
    cmp.max_command_um_last_10k = std::max(cmp.max_command_um_last_10k, diff_um[k]);
  return cmp;
}

void print(const char* name, const Comparison& c) {
  std::printf(
      "mcu: firmware against %s:\n"
      "  max |dDAC| %.3g V, max |du| %.3g nm at tick %u; max |du| over the 10 000 ticks "
      "after the last saturated tick (%u) %.3g nm, over the last 10 000 ticks %.3g nm; "
      "saturated ticks %u, saturation flags differing on %u\n",
      name, c.max_dac_V, c.max_command_um * 1e3, c.max_at_tick, c.last_saturated_tick,
      c.max_command_um_next_10k * 1e3, c.max_command_um_last_10k * 1e3, c.saturated_ticks,
      c.mask_mismatches);
}

// The cross-compiled float controller computes exactly what the same template computes in float
// on the host: IEEE single precision on both sides, one rounding per operation (the firmware is
// built with -ffp-contract=off, so no fused multiply-add), no double anywhere in the firmware.
TEST(McuFirmware, EqualsTheHostFloatControllerBitForBit) {
  const FirmwareRun& run = firmware_run();
  ASSERT_GE(test_vector().header.ticks, 100000U);
  const Comparison c =
      compare(run, FloatController(control::convert<float>(SemiClosedLoopParams{})));
  print("the host float controller", c);
  EXPECT_EQ(c.max_dac_V, 0.0);
  EXPECT_EQ(c.max_command_um, 0.0);
  EXPECT_EQ(c.mask_mismatches, 0U);
  EXPECT_GT(c.saturated_ticks, 100U);  // the vector exercises the clamp
}

// The float firmware against the host's double controller on the same recorded inputs. The replay
// is open loop: nothing feeds the firmware's output back, so the incremental PID's u(k) integrates
// every difference of e(k) = S - y. S = A p(Z_d) in float differs from double by about one float
// ulp and stays the same through a hold, so u drifts apart by ki x ulp(S) per tick: 0.2 x 4.8e-7
// um = 0.1 nm per second at 1 kHz for S of 4 to 8 um. The tolerance is that drift at its worst,
// every tick carrying one ulp of [8, 16) um (9.5e-7 um) of the same sign: ki x N x ulp(16 um), 23
// nm over 120 000 ticks. In closed loop the feedback removes it (ClosedLoopOnTheTwin below).
TEST(McuFirmware, MatchesTheHostDoubleControllerWithinTheOpenLoopReplayBound) {
  const FirmwareRun& run = firmware_run();
  const std::uint32_t n = test_vector().header.ticks;
  const Comparison c = compare(run, SemiClosedLoopController{});
  print("the host double controller (open-loop replay)", c);
  const double ulp_um = std::ldexp(1.0, 3 - 23);  // float spacing in [8, 16) um: 9.5e-7 um
  const double tolerance_um = 0.2 * n * ulp_um;
  EXPECT_LT(c.max_command_um, tolerance_um);
  EXPECT_LT(c.max_dac_V, tolerance_um * 0.625);
  // Right after the saturated move both clamp to the same exact 16 um, so they restart equal.
  EXPECT_LT(c.max_command_um_next_10k, 1e-3);
  EXPECT_EQ(c.mask_mismatches, 0U);
}

// What the open-loop drift means for the stage: the float and the double controller each close
// the loop on their own twin (same seed, so the same noise), with the vector's set-point
// programme. Both see the 16-bit ADC codes and drive the 16-bit DAC; a float difference reaches
// the stage only when it flips a DAC code (one LSB, 0.305 mV, is 0.49 nm of command), and the
// loop then pulls it back. So the stage positions differ by well under 1 nm throughout.
TEST(McuFirmware, FloatAndDoubleControllersHoldTheTwinAlikeInClosedLoop) {
  const TestVector& v = test_vector();
  plant::Twin twin_d({}, {}, v.header.seed);
  plant::Twin twin_f({}, {}, v.header.seed);
  SemiClosedLoopController c_d;
  FloatController c_f(control::convert<float>(SemiClosedLoopParams{}));
  double max_points_nm = 0.0;
  double max_points_settled_nm = 0.0;  // from 0.2 s after a set-point change (settled: 0.033 s)
  double sum_sq_points_nm2 = 0.0;
  double max_command_nm = 0.0;
  std::array<double, 3> sum_last_nm{};  // signed, over the last 10 000 ticks: a drift is a bias
  double sum_sq_last_nm2 = 0.0;
  const std::uint32_t last_from = v.header.ticks - 10000;
  std::uint64_t dac_differs = 0;
  std::size_t seg = 0;
  for (std::uint32_t k = 0; k < v.header.ticks; ++k) {
    const float* z = v.zd_um(k, seg);
    const bool settled = k >= v.segments[seg].start_tick + 200;
    const Vec3 ai_d = twin_d.read_ai();
    const Vec3 ai_f = twin_f.read_ai();
    const auto out_d = c_d.update(Vec3{z[0], z[1], z[2]}, ai_d);
    const auto out_f =
        c_f.update(FloatController::Vec{z[0], z[1], z[2]}, control::convert<float>(ai_f));
    twin_d.write_ao(out_d.dac_V);
    twin_d.advance();
    twin_f.write_ao(control::convert<double>(out_f.dac_V));
    twin_f.advance();
    if (twin_d.truth().ao_V != twin_f.truth().ao_V)
      ++dac_differs;
    for (std::size_t i = 0; i < 3; ++i) {
      const double signed_nm = 1e3 * (twin_f.truth().points_um[i] - twin_d.truth().points_um[i]);
      const double d_nm = std::fabs(signed_nm);
      max_points_nm = std::max(max_points_nm, d_nm);
      if (k >= last_from) {
        sum_last_nm[i] += signed_nm;
        sum_sq_last_nm2 += d_nm * d_nm;
      }
      if (settled)
        max_points_settled_nm = std::max(max_points_settled_nm, d_nm);
      sum_sq_points_nm2 += d_nm * d_nm;
      max_command_nm = std::max(max_command_nm,
                                1e3 * std::fabs(out_d.command_um[i] - double{out_f.command_um[i]}));
    }
  }
  std::printf(
      "mcu: closed loop on the twin, float against double controller, %u ticks: "
      "measurement points P1..P3 differ by max %.3g nm (%.3g nm from 0.2 s after a "
      "set-point change); commands by max %.3g nm; DAC codes differ on %.3g %% of "
      "ticks\n",
      v.header.ticks, max_points_nm, max_points_settled_nm, max_command_nm,
      100.0 * static_cast<double>(dac_differs) / v.header.ticks);
  const double rms_nm = std::sqrt(sum_sq_points_nm2 / (3.0 * v.header.ticks));
  const double rms_last_nm = std::sqrt(sum_sq_last_nm2 / 30000.0);
  double max_bias_last_nm = 0.0;
  for (double sum : sum_last_nm)
    max_bias_last_nm = std::max(max_bias_last_nm, std::fabs(sum / 10000.0));
  std::printf(
      "mcu: over the last 10 000 ticks: rms %.3g nm, mean (a drift would show here) max "
      "%.3g nm\n",
      rms_last_nm, max_bias_last_nm);
  // The two loops jitter apart by about one DAC LSB (0.45 nm at the stack) with the sensor noise;
  // they do not drift apart: the mean difference at the end is a small part of that.
  EXPECT_LT(rms_nm, 1.0);
  EXPECT_LT(rms_last_nm, 1.0);
  EXPECT_LT(max_bias_last_nm, 0.2);
  EXPECT_LT(max_points_settled_nm, 5.0);
  EXPECT_LT(max_command_nm, 2.0);
}

TEST(McuFirmware, ControllerTickCostUnderIcount) {
  const FirmwareRun& run = firmware_run();
  const RunStats& s = run.stats;
  ASSERT_EQ(s.magic, kStatsMagic);
  ASSERT_EQ(s.ticks, test_vector().header.ticks);
  // Under -icount shift=0 the virtual clock runs 1 ns per instruction and the STM32F405 model's
  // SysTick counts its 168 MHz core clock: 0.168 counts per instruction. The figures below rest
  // on it, so it is checked (a loop of 2 000 000 instructions, to one count).
  const double counts_per_instruction =
      static_cast<double>(s.calibration_counts) / static_cast<double>(s.calibration_instructions);
  EXPECT_NEAR(counts_per_instruction, 0.168, 1e-6);
  const double insn_per_tick =
      static_cast<double>(s.update_counts - s.empty_counts) / counts_per_instruction / s.ticks;
  const double insn_max = (s.update_counts_max - s.empty_counts_min) / counts_per_instruction;
  const double insn_min = (s.update_counts_min - s.empty_counts_max) / counts_per_instruction;
  std::printf(
      "mcu: controller tick (call, feedforward, three PIDs, scaling): %.1f instructions "
      "on average over %u ticks, min %.0f, max %.0f (a SysTick count is 5.95 "
      "instructions)\n",
      insn_per_tick, s.ticks, insn_min, insn_max);
  // A sanity check of the measurement, not a speed target (docs/performance.md has the figures).
  EXPECT_GT(insn_per_tick, 100.0);
  EXPECT_LT(insn_per_tick, 5000.0);
}

}  // namespace
}  // namespace piezoshift::firmware
