// The paper's controller on a Cortex-M4F (STM32F405 under QEMU netduinoplus2), in float: replays
// the recorded test vector tick by tick, writes every tick's outputs to a host file and times the
// controller update with SysTick. The outputs are compared with the host's double controller by
// tests/mcu/mcu_equivalence_test.cpp; docs/mcu.md.
//
//   qemu-system-arm -M netduinoplus2 -icount shift=0 -kernel piezoshift_firmware.elf
//     -semihosting-config enable=on,target=native,arg=piezoshift_firmware,arg=OUT.bin
//
// Exit status: 0 done, 1 bad vector, 2 no output file, 3 a fault.
#include <cstdint>
#include <cstring>

#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/firmware/test_vector.hpp"
#include "semihosting.hpp"

extern "C" const unsigned char g_test_vector_begin[];
extern "C" const unsigned char g_test_vector_end[];

namespace {

namespace control = piezoshift::control;
namespace fw = piezoshift::firmware;

using Controller = control::BasicSemiClosedLoopController<float>;
using Vec = Controller::Vec;

// The host's double parameters (the paper's defaults), rounded to float once, at compile time.
constexpr Controller::Params kParams = control::convert<float>(control::SemiClosedLoopParams{});

// The controller lives in .data: its RAM is sizeof(Controller). Constant-initialized, so no
// constructor runs at start-up.
Controller g_controller{kParams};

// One controller tick, kept out of line so that its code size can be read from the symbol table
// (arm-none-eabi-nm -S) and its cost includes the call, as a timer interrupt handler's would.
[[gnu::noinline]] Controller::Output controller_tick(const Vec& zd_um, const Vec& sgs_V) noexcept {
  return g_controller.update(zd_um, sgs_V);
}

// SysTick, free-running at the core clock (CLKSOURCE = 1), 24-bit down-counter.
volatile std::uint32_t& syst_csr = *reinterpret_cast<volatile std::uint32_t*>(0xE000E010);
volatile std::uint32_t& syst_rvr = *reinterpret_cast<volatile std::uint32_t*>(0xE000E014);
volatile std::uint32_t& syst_cvr = *reinterpret_cast<volatile std::uint32_t*>(0xE000E018);
constexpr std::uint32_t kSysTickMask = 0x00FFFFFF;

void systick_start() noexcept {
  syst_rvr = kSysTickMask;
  syst_cvr = 0;
  syst_csr = 0b101;  // enable, processor clock, no interrupt
}

//! Counts elapsed from a to b (the counter counts down and wraps at 2^24).
std::uint32_t elapsed(std::uint32_t a, std::uint32_t b) noexcept {
  return (a - b) & kSysTickMask;
}

// Keeps the compiler from moving work across a timer read: everything reachable from p is in
// memory before, and read again after.
inline void fence(const void* p) noexcept {
  asm volatile("" : : "r"(p) : "memory");
}

//! Timer counts per instruction, from a loop of exactly 2 n instructions (subs, bne).
void calibrate(fw::RunStats& stats) noexcept {
  constexpr std::uint32_t kIterations = 1000000;
  std::uint32_t n = kIterations;
  const std::uint32_t t0 = syst_cvr;
  asm volatile("1: subs %0, %0, #1\n\tbne 1b" : "+r"(n) : : "cc");
  const std::uint32_t t1 = syst_cvr;
  stats.calibration_instructions = 2ULL * kIterations;
  stats.calibration_counts = elapsed(t0, t1);
}

struct Inputs {
  Vec zd_um{};
  Vec sgs_V{};
};

class Replay {
 public:
  explicit Replay(const fw::VectorHeader& h) noexcept
      : h_(h),
        segments_(reinterpret_cast<const fw::SetpointSegment*>(g_test_vector_begin +
                                                               fw::segments_offset())),
        codes_(reinterpret_cast<const std::int16_t*>(g_test_vector_begin + fw::codes_offset(h))) {}

  void at(std::uint32_t k, Inputs& in) noexcept {
    while (seg_ + 1 < h_.segments && segments_[seg_ + 1].start_tick <= k)
      ++seg_;
    for (std::size_t i = 0; i < control::kChannels; ++i) {
      in.zd_um[i] = segments_[seg_].zd_um[i];
      in.sgs_V[i] = static_cast<float>(codes_[3 * k + i]) * h_.ai_lsb_V;  // exact in float
    }
  }

 private:
  const fw::VectorHeader& h_;
  const fw::SetpointSegment* segments_;
  const std::int16_t* codes_;
  std::uint32_t seg_ = 0;
};

bool vector_ok(const fw::VectorHeader& h) noexcept {
  const auto bytes = static_cast<std::size_t>(g_test_vector_end - g_test_vector_begin);
  return bytes >= sizeof h && h.magic == fw::kVectorMagic && h.version == fw::kFormatVersion &&
         h.segments > 0 && fw::vector_size(h) == bytes;
}

//! The second argument of the semihosting command line: the output file.
bool output_path(char* path, std::size_t bytes) noexcept {
  char line[256] = {};
  if (!fw::semihosting_command_line(line, sizeof line))
    return false;
  const char* p = std::strchr(line, ' ');
  if (p == nullptr)
    return false;
  ++p;
  std::size_t n = 0;
  while (p[n] != '\0' && p[n] != ' ' && n + 1 < bytes) {
    path[n] = p[n];
    ++n;
  }
  path[n] = '\0';
  return n > 0;
}

void line(fw::HostFile& out, const char* key, std::uint64_t value) noexcept {
  out.text(key);
  out.number(value);
  out.text("\n");
}

}  // namespace

int main() {
  // The emulation's I/O buffers (4 KiB each) live in .bss, not on the stack.
  static fw::HostFile console(fw::semihosting_open(":tt", false));
  fw::VectorHeader h;
  std::memcpy(&h, g_test_vector_begin, sizeof h);
  if (!vector_ok(h)) {
    console.text("firmware: bad test vector\n");
    console.flush();
    return 1;
  }
  char path[200] = {};
  if (!output_path(path, sizeof path)) {
    console.text("firmware: no output file on the semihosting command line\n");
    console.flush();
    return 2;
  }
  static fw::HostFile out(fw::semihosting_open(path, true));
  if (!out.ok()) {
    console.text("firmware: cannot open the output file\n");
    console.flush();
    return 2;
  }

  fw::RunStats stats;
  stats.ticks = h.ticks;
  systick_start();
  calibrate(stats);

  // Pass 1: every tick through the controller, each update timed, each output written.
  Replay replay(h);
  Inputs in;
  stats.update_counts_min = kSysTickMask;
  for (std::uint32_t k = 0; k < h.ticks; ++k) {
    replay.at(k, in);
    fence(&in);
    const std::uint32_t t0 = syst_cvr;
    fence(&in);
    const Controller::Output o = controller_tick(in.zd_um, in.sgs_V);
    fence(&o);
    const std::uint32_t dt = elapsed(t0, syst_cvr);
    stats.update_counts += dt;
    stats.update_counts_max = dt > stats.update_counts_max ? dt : stats.update_counts_max;
    stats.update_counts_min = dt < stats.update_counts_min ? dt : stats.update_counts_min;
    fw::TickRecord r;
    for (std::size_t i = 0; i < control::kChannels; ++i) {
      r.dac_V[i] = o.dac_V[i];
      r.command_um[i] = o.command_um[i];
    }
    r.saturated_mask = o.saturated_mask;
    out.write(&r, sizeof r);
  }

  // Pass 2: the same timing around nothing, for the cost of the measurement itself.
  Replay empty(h);
  stats.empty_counts_min = kSysTickMask;
  for (std::uint32_t k = 0; k < h.ticks; ++k) {
    empty.at(k, in);
    fence(&in);
    const std::uint32_t t0 = syst_cvr;
    fence(&in);
    fence(&in);
    const std::uint32_t dt = elapsed(t0, syst_cvr);
    stats.empty_counts += dt;
    stats.empty_counts_max = dt > stats.empty_counts_max ? dt : stats.empty_counts_max;
    stats.empty_counts_min = dt < stats.empty_counts_min ? dt : stats.empty_counts_min;
  }

  out.write(&stats, sizeof stats);
  out.flush();
  const bool written = out.ok();
  out.close();

  console.text("firmware: BasicSemiClosedLoopController<float> on Cortex-M4F\n");
  line(console, "ticks=", h.ticks);
  line(console, "controller_ram_bytes=", sizeof(Controller));
  line(console, "calibration_instructions=", stats.calibration_instructions);
  line(console, "calibration_counts=", stats.calibration_counts);
  line(console, "update_counts=", stats.update_counts);
  line(console, "update_counts_max=", stats.update_counts_max);
  line(console, "empty_counts=", stats.empty_counts);
  console.text(written ? "firmware: outputs written\n" : "firmware: writing outputs failed\n");
  console.flush();
  return written ? 0 : 2;
}
