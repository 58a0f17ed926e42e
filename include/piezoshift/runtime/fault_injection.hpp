#pragma once
// Fault injection on the sim backend: a DaqBackend decorator that corrupts what the loop reads,
// what the twin receives, or the loop's time, from a given time on.
//
//   --fault KIND@T_S[:CHANNEL]     CHANNEL 1..3 (default 1; not for overrun-burst)
//
//   kind             from tick f = first tick with t >= T_S on             caught by
//   (docs/safety.md) sgs-open         the gauge bridge opens: the conditioner goes to its sgs-rail
//                    positive rail (the twin: 12 V), the +-10 V ADC clips
//   sgs-stuck        the conditioner's output freezes at its last value     response / tracking,
//   once
//                                                                           the stage is moved
//   adc-nan          AI[ch] = NaN (a failed conversion)                     sgs-not-finite
//   adc-spike        tick f only: AI[ch] += spike_V towards the far end of  sgs-jump (sgs-rail when
//                    the range (+ below 5 V, - above), clipped at +-10 V    it clips)
//   amplifier-fail   the amplifier of ch stops driving: its stack           response / tracking
//                    discharges through the amplifier
//   actuator-crack   the stack of ch keeps crack_stiffness_factor of its    response / tracking
//                    stiffness (needs a plant model)
//   overrun-burst    ticks f .. f+burst-1 each stall the loop for            overruns
//                    overrun_stall_periods periods (clock.stall_ns)
//
// A plant model (PlantFaultHooks, the twin) shows the channel faults in its own physics; without
// one the injector emulates the sensor faults on the AI values and amplifier-fail by sending
// 0 V to that channel.
//
// read() and write() are real-time safe; parsing and construction are set-up.
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "piezoshift/runtime/daq_backend.hpp"
#include "piezoshift/runtime/loop_clock.hpp"

namespace piezoshift::runtime {

enum class FaultKind : std::uint8_t {
  kSgsOpen,
  kSgsStuck,
  kAdcNan,
  kAdcSpike,
  kAmplifierFail,
  kActuatorCrack,
  kOverrunBurst,
};
inline constexpr std::size_t kFaultKinds = 7;

const char* to_string(FaultKind kind) noexcept;

struct FaultSpec {
  FaultKind kind = FaultKind::kSgsOpen;
  double time_s = 0.0;
  int channel = 0;  //!< 0..2 (CLI 1..3); -1 for overrun-burst
};

//! The longest timed run `run` accepts (--duration-s, 11.6 days), and so the latest injection
//! time (later times overflowed the nanosecond clock and were injected at tick 0).
inline constexpr double kMaxRunDurationS = 1e6;

//! Parses "KIND@T_S[:CHANNEL]", T_S in [0, kMaxRunDurationS]; throws core::InputError naming the
//! text and what is wrong.
FaultSpec parse_fault_spec(std::string_view text);

struct FaultInjectionParams {
  double spike_V = 6.0;                   //!< one-sample spike amplitude
  double adc_full_scale_V = 10.0;         //!< a spike clips here, as the ADC would
  double crack_stiffness_factor = 0.05;   //!< k_a after the crack / k_a before
  double overrun_stall_periods = 1.5;     //!< each burst tick takes this many periods
  std::uint32_t overrun_burst_ticks = 5;  //!< > SafetyLimits::max_consecutive_overruns
};

//! A plant model that can show faults itself (the twin). inject() is called once, from read(),
//! when a channel fault starts, before the plant is stepped for that tick's samples.
class PlantFaultHooks {
 public:
  virtual ~PlantFaultHooks() = default;
  //! Makes the plant show the fault on channel (0..2); false when it does not model this kind
  //! (the injector then emulates it at the DAQ boundary).
  virtual bool inject(FaultKind kind, std::size_t channel,
                      const FaultInjectionParams& params) noexcept = 0;
};

class FaultInjectingBackend final : public DaqBackend {
 public:
  static constexpr std::uint64_t kNotYet = std::numeric_limits<std::uint64_t>::max();

  //! hooks may be null: actuator-crack is then refused here (core::InputError).
  FaultInjectingBackend(DaqBackend& inner, LoopClock& clock, std::int64_t period_ns,
                        std::vector<FaultSpec> faults, FaultInjectionParams params = {},
                        PlantFaultHooks* hooks = nullptr);

  void configure() override { inner_.configure(); }
  void activate() override;
  void deactivate() noexcept override { inner_.deactivate(); }
  DaqStatus read(const CycleTime& t, Vec3& ai_V) noexcept override;
  DaqStatus write(const CycleTime& t, const Vec3& ao_V) noexcept override;
  std::string name() const override { return inner_.name(); }
  bool truth(Vec3& z_um, Vec3& interferometer_um) const noexcept override {
    return inner_.truth(z_um, interferometer_um);
  }
  double fringe_drift_nm() const noexcept override { return inner_.fringe_drift_nm(); }
  bool has_trigger_line() const noexcept override { return inner_.has_trigger_line(); }
  void stage_trigger_line(bool high) noexcept override { inner_.stage_trigger_line(high); }
  bool take_trigger_edge(TriggerEdge& edge) noexcept override {
    return inner_.take_trigger_edge(edge);
  }

  const std::vector<FaultSpec>& faults() const noexcept { return faults_; }
  //! The tick at which fault i started, or kNotYet.
  std::uint64_t injected_tick(std::size_t i) const noexcept { return started_[i]; }
  //! The earliest start tick of any fault, or kNotYet.
  std::uint64_t first_injected_tick() const noexcept;

 private:
  DaqBackend& inner_;
  LoopClock& clock_;
  std::int64_t period_ns_;
  std::vector<FaultSpec> faults_;
  std::vector<std::int64_t> start_ns_;
  std::vector<std::uint64_t> started_;
  std::vector<bool> emulated_;  // fault i is emulated here, not by the plant
  FaultInjectionParams params_;
  PlantFaultHooks* hooks_;
  std::uint64_t amplifier_dead_mask_ = 0;  // channels whose AO is forced to 0 (emulated)
  Vec3 frozen_V_{};                        // last healthy AI per channel (emulated sgs-stuck)
};

}  // namespace piezoshift::runtime
