#pragma once
// The `sim` backend: the digital twin (plant::Twin) behind the DAQ interface, advanced in step
// with the loop's clock. Per tick, keeping the board's timing contract (daq_backend.hpp):
//
//   read(t):   n = period_ns / T (1, or more after skipped slots; at most kMaxCatchUpPeriods)
//              n x twin.advance()      physics over the elapsed periods with the AO held that
//                                      went out at the previous tick; ends with the AI sample
//              ai = twin.read_ai()
//              twin.write_ao(staged)   the outputs of the last write() go out now
//   write(t):  staged = ao
//
// so the twin sees the same one-transaction-per-tick timing as the Comedi backend. The twin runs
// at the loop's rate: its DAQ period is the loop period and its physics rate the smallest whole
// multiple of the loop rate at or above the twin's physics_rate_Hz (20 kHz by default).
//
// Faults (PlantFaultHooks): every channel fault kind is shown by the twin itself (its
// ChannelFault): sgs-open, sgs-stuck, adc-nan, adc-spike, amplifier-fail, actuator-crack. A
// stiffness change re-discretizes the twin's mechanics: inject() is then not real-time safe,
// which only fault-injection runs ever do.
//
// The trigger line: the twin has one, a wire to the twin camera. read() puts the staged level out
// with the AO and records each rising edge (its tick and scheduled time) in a fixed-size
// lock-free ring (kWireEdges; an edge that finds it full is counted, not kept) that the owner
// thread drains with take_trigger_edge() and hands to the camera's trigger(): the wire.
//
// read()/write()/truth()/stage_trigger_line() are real-time safe; configure() builds the twin
// (allocates, throws core::InputError for parameters that cannot make one).
#include <cstdint>
#include <memory>
#include <string>

#include "piezoshift/design/design_inputs.hpp"
#include "piezoshift/plant/twin.hpp"
#include "piezoshift/plant/twin_params.hpp"
#include "piezoshift/runtime/daq_backend.hpp"
#include "piezoshift/runtime/fault_injection.hpp"
#include "piezoshift/runtime/spsc_ring.hpp"

namespace piezoshift::runtime {

struct SimOptions {
  design::DesignInputs design{};
  plant::TwinParams twin{};
  std::uint64_t seed = 1;
  double rate_Hz = 1000.0;  //!< the loop's rate; the twin's DAQ period is 1 / rate_Hz
  //! Where design and twin came from (a configuration file), for messages.
  std::string source = "the built-in configuration";
};

//! The twin's parameters at a DAQ period: that period, and the physics rate rounded up to the
//! smallest whole multiple of the DAQ rate at or above the configured one. Also the emulated
//! Comedi board's (emulation/comedi), so both put the same twin on their wires.
plant::TwinParams twin_params_at_period(plant::TwinParams p, std::int64_t period_ns);

class SimBackend final : public DaqBackend, public PlantFaultHooks {
 public:
  explicit SimBackend(SimOptions options);
  ~SimBackend() override;

  void configure() override;
  void activate() override;
  void deactivate() noexcept override;
  //! Periods one read() advances at most after skipped slots: so a twin slower than real time
  //! (the heaviest physics the ranges accept) cannot make each tick longer than the one before.
  static constexpr std::int64_t kMaxCatchUpPeriods = 10;

  DaqStatus read(const CycleTime& t, Vec3& ai_V) noexcept override;
  DaqStatus write(const CycleTime& t, const Vec3& ao_V) noexcept override;
  std::string name() const override { return "sim"; }
  bool truth(Vec3& z_um, Vec3& interferometer_um) const noexcept override;
  double fringe_drift_nm() const noexcept override;

  bool has_trigger_line() const noexcept override { return true; }
  void stage_trigger_line(bool high) noexcept override { line_staged_ = high; }
  bool take_trigger_edge(TriggerEdge& edge) noexcept override { return wire_.try_pop(edge); }
  //! Rising edges the wire can hold before the owner takes them.
  static constexpr std::size_t kWireEdges = 64;
  //! Rising edges put out since configure(), and those lost to a full wire.
  std::uint64_t trigger_edges() const noexcept { return edges_; }
  std::uint64_t trigger_edges_dropped() const noexcept { return edges_dropped_; }
  //! The line's level as it went out at the last read().
  bool trigger_line_high() const noexcept { return line_high_; }

  bool inject(FaultKind kind, std::size_t channel,
              const FaultInjectionParams& params) noexcept override;

  //! The twin (after configure()).
  const plant::Twin& twin() const { return *twin_; }
  std::int64_t period_ns() const noexcept { return period_ns_; }

 private:
  SimOptions options_;
  std::int64_t period_ns_ = 0;
  std::unique_ptr<plant::Twin> twin_;
  Vec3 staged_{};
  Vec3 last_ai_{};
  bool active_ = false;
  bool line_staged_ = false;
  bool line_high_ = false;
  SpscRing<TriggerEdge> wire_{kWireEdges};
  std::uint64_t edges_ = 0;
  std::uint64_t edges_dropped_ = 0;
};

}  // namespace piezoshift::runtime
