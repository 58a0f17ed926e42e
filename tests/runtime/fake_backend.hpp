#pragma once
// A small test-only plant behind the DaqBackend interface, with the same timing contract as the
// real backends: read() applies the outputs staged by the last write(), advancing the plant by
// the tick's period with the previously applied outputs held, then samples.
//
//   per channel:  x_cmd = (ao_V / 0.625 V/um)            um of command (drive scaling)
//                 x    += (G x_cmd - x) (1 - exp(-h / tau))   first-order stage, G from Eq. 1
//                 sgs_V = x / 1.6 um/V
// with G = f k_a / (f k_a + k_m) (f = 1, or the crack's stiffness factor) and a dead amplifier
// giving x_cmd = 0. Not a model of anything more: the supervisor and loop tests need a plant
// whose answers are known in closed form.
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>

#include "piezoshift/runtime/daq_backend.hpp"
#include "piezoshift/runtime/fault_injection.hpp"

namespace piezoshift::runtime::testing {

class FakeBackend final : public DaqBackend, public PlantFaultHooks {
 public:
  static constexpr double kStiffnessActuator = 70.0;   // N/um, Table 1
  static constexpr double kStiffnessMechanism = 6.78;  // N/um, Section 2.2
  double tau_s = 0.5e-3;

  void configure() override { configured = true; }
  void activate() override {
    active = true;
    applied_ = staged_ = Vec3{};
  }
  void deactivate() noexcept override {
    active = false;
    applied_ = staged_ = Vec3{};
    ++deactivations;
  }
  DaqStatus read(const CycleTime& t, Vec3& ai_V) noexcept override {
    if (!active)
      return DaqStatus::kInactive;
    const double h = static_cast<double>(t.period_ns) * 1e-9;
    const double a = 1.0 - std::exp(-h / tau_s);
    for (std::size_t i = 0; i < 3; ++i) {
      const double x_cmd = dead_[i] ? 0.0 : applied_[i] / 0.625;
      x_um_[i] += (gain(i) * x_cmd - x_um_[i]) * a;
      ai_V[i] = x_um_[i] / 1.6;
    }
    applied_ = staged_;
    if (line_staged_ && !line_high_ && rising_edges < static_cast<int>(rising_ticks.size()))
      rising_ticks[static_cast<std::size_t>(rising_edges)] = t.tick;
    if (line_staged_ && !line_high_)
      ++rising_edges;
    line_high_ = line_staged_;
    if (line_high_)
      ++high_ticks;
    ++reads;
    if (signal_flag != nullptr && t.tick == signal_tick)
      signal_flag->store(15);
    if (on_tick != nullptr && t.tick == on_tick_at)
      on_tick(on_tick_context);
    return fail_reads ? DaqStatus::kError : DaqStatus::kOk;
  }
  DaqStatus write(const CycleTime&, const Vec3& ao_V) noexcept override {
    if (!active)
      return DaqStatus::kInactive;
    staged_ = ao_V;
    last_written = ao_V;
    return DaqStatus::kOk;
  }
  std::string name() const override { return "fake"; }
  bool has_trigger_line() const noexcept override { return trigger_line; }
  void stage_trigger_line(bool high) noexcept override {
    line_staged_ = high;
    ++line_stages;
  }
  bool truth(Vec3& z_um, Vec3& interferometer_um) const noexcept override {
    z_um = x_um_;
    interferometer_um = x_um_;
    return true;
  }

  //! The fake models the two plant faults; the injector emulates the sensor faults.
  bool inject(FaultKind kind, std::size_t ch, const FaultInjectionParams& p) noexcept override {
    if (kind == FaultKind::kAmplifierFail) {
      dead_[ch] = true;
      return true;
    }
    if (kind == FaultKind::kActuatorCrack) {
      stiffness_factor_[ch] = p.crack_stiffness_factor;
      return true;
    }
    return false;
  }

  double gain(std::size_t i) const {
    const double ka = stiffness_factor_[i] * kStiffnessActuator;
    return ka / (ka + kStiffnessMechanism);
  }
  const Vec3& stage_um() const { return x_um_; }

  // Test hooks, called from read(): raise a "signal" or run a function at a given tick.
  std::atomic<int>* signal_flag = nullptr;
  std::uint64_t signal_tick = 0;
  void (*on_tick)(void*) = nullptr;
  void* on_tick_context = nullptr;
  std::uint64_t on_tick_at = 0;

  bool configured = false;
  bool active = false;
  bool fail_reads = false;
  int reads = 0;
  int deactivations = 0;
  Vec3 last_written{};
  // The trigger line (when trigger_line): stage calls, reads that put it out high, rising edges
  // (the first ticks of up to 8 of them).
  bool trigger_line = false;
  int line_stages = 0;
  int high_ticks = 0;
  int rising_edges = 0;
  std::array<std::uint64_t, 8> rising_ticks{};
  bool line_high() const { return line_high_; }

 private:
  Vec3 x_um_{};
  Vec3 applied_{};
  Vec3 staged_{};
  bool line_staged_ = false;
  bool line_high_ = false;
  std::array<bool, 3> dead_{};
  Vec3 stiffness_factor_{1.0, 1.0, 1.0};
};

}  // namespace piezoshift::runtime::testing
