#pragma once
// The wave generators of `piezoshift serve` on the real-time side (GCS WGO, docs/gcs.md): up to
// kGenerators tables played into the loop's set-point, one table point every `rate` ticks (WTR),
// sample-exact, for `cycles` passes (0: until stopped).
//
//   generator g running, k ticks after its start command was applied:
//     w_g(k)   = values[(k / rate) mod length]
//     Z_d(k)   = base + sum over running g of  points_per_unit_g * (w_g(k) - reference_g)
//   base is the set-point the host's moves gave (it already holds reference_g for axis g, so the
//   generator replaces that axis's contribution). When a generator stops (its cycles are done, a
//   stop command, or `enabled` false: servo off or a fault), its last output is folded into base,
//   so the set-point stays where the wave left it, as a PI controller leaves the axis there.
//
// Table lifetime (real-time safety): `values` points into storage the host owns and allocated
// before the loop started (host::WaveSlots). The host writes a slot only while no generator can
// read it: a slot is handed over in a WaveCommand through the lock-free command ring (its release
// and acquire order the table writes before the loop's reads) and is free again once the loop has
// applied the next start or stop of that generator (HostSample::applied_sequence). The loop never
// copies, allocates, locks or waits here; every member is fixed-size.
#include <array>
#include <cstddef>
#include <cstdint>

#include "piezoshift/control/vec3.hpp"

namespace piezoshift::runtime {

struct WaveCommand {
  enum class Action : std::uint8_t { kStart, kStop };
  Action action = Action::kStop;
  std::uint8_t generator = 0;       //!< 0 .. kGenerators-1 (the axis it drives)
  const double* values = nullptr;   //!< kStart: the table, axis units; see the lifetime above
  std::uint32_t length = 0;         //!< kStart: points in values, >= 1
  std::uint32_t rate = 1;           //!< ticks per table point (WTR), >= 1
  std::uint32_t cycles = 1;         //!< passes through the table; 0: until stopped
  control::Vec3 points_per_unit{};  //!< d Z_d / d axis value (the tripod's column for the axis)
  double reference = 0.0;           //!< the axis value the host's set-point already holds
                                    //!< (ignored when the generator runs: it keeps its own)
};

class WaveGenerator {
 public:
  static constexpr std::size_t kGenerators = 3;

  //! Start (restarts a running one from its first point) or stop one generator. Real-time
  //! safe.
  void apply(const WaveCommand& c, control::Vec3& base) noexcept {
    if (c.generator >= kGenerators)
      return;
    Playback& p = playing_[c.generator];
    const bool start =
        c.action == WaveCommand::Action::kStart && c.values != nullptr && c.length > 0;
    if (p.running && !start) {
      fold(p, base);
      p.running = false;
      return;
    }
    if (!start)
      return;
    // A restart keeps the reference base already holds (the host's target is still it).
    const double reference = p.running ? p.reference : c.reference;
    p = Playback{};
    p.running = true;
    p.values = c.values;
    p.length = c.length;
    p.rate = c.rate > 0 ? c.rate : 1;
    p.cycles = c.cycles;
    p.points_per_unit = c.points_per_unit;
    p.reference = reference;
    p.last = reference;
  }

  //! The set-point of this tick (see the header comment), and one tick on. With enabled false,
  //! stops every generator first. Real-time safe.
  control::Vec3 next(control::Vec3& base, bool enabled) noexcept {
    control::Vec3 zd = base;
    for (Playback& p : playing_) {
      if (!p.running)
        continue;
      if (!enabled) {
        fold(p, base);
        p.running = false;
        continue;
      }
      const std::uint64_t point = p.tick / p.rate;
      p.last = p.values[point % p.length];
      for (std::size_t i = 0; i < zd.size(); ++i)
        zd[i] += p.points_per_unit[i] * (p.last - p.reference);
      ++p.tick;
      const std::uint64_t total = std::uint64_t{p.cycles} * p.length * p.rate;
      if (p.cycles != 0 && p.tick >= total) {
        fold(p, base);  // done: hold the last point, as the next ticks' set-point
        p.running = false;
      }
    }
    if (!enabled)
      zd = base;
    return zd;
  }

  //! Bit g set while generator g runs (GCS #9).
  std::uint8_t running_mask() const noexcept {
    std::uint8_t mask = 0;
    for (std::size_t g = 0; g < kGenerators; ++g)
      if (playing_[g].running)
        mask = static_cast<std::uint8_t>(mask | (1u << g));
    return mask;
  }

 private:
  struct Playback {
    bool running = false;
    const double* values = nullptr;
    std::uint32_t length = 0;
    std::uint32_t rate = 1;
    std::uint32_t cycles = 0;
    std::uint64_t tick = 0;
    control::Vec3 points_per_unit{};
    double reference = 0.0;
    double last = 0.0;  // the output last played
  };

  static void fold(const Playback& p, control::Vec3& base) noexcept {
    for (std::size_t i = 0; i < base.size(); ++i)
      base[i] += p.points_per_unit[i] * (p.last - p.reference);
  }

  std::array<Playback, kGenerators> playing_{};
};

}  // namespace piezoshift::runtime
