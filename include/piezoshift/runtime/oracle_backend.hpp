#pragma once
// The oracle: the twin with a perfect sensor, a backend no hardware can be. Each read() runs the
// twin's tick (sim_backend.hpp) and then replaces the three AI samples with the plate's true
// displacements at the measurement points P1..P3, mapped to the actuators the controller feeds
// back and expressed in the conditioner's volts:
//
//   ai_i = sgs_offset_V_i + (A z_true)_i / sgs_um_per_V_i
//
// With the feedforward's polynomial set to the identity, the controller's actuator targets are
// S = A Z_d, so each PID drives (A (Z_d - z_true))_i to zero: the same loop, closed on the plate
// itself instead of the stacks' strain gauges. Everything between gauge and plate (contact,
// gauge creep and drift, conditioner nonlinearity and noise) is gone; what is left is the
// plant's own dynamics, the amplifier, the DAQ's outputs and the interferometer that scores the
// result. That is the floor no controller fed by the gauges can beat. Labelled impossible on
// hardware wherever it is reported.
//
// notches (docs/control.md): where the PID closed on the plate rings at the plate's modes,
// compare's oracle may take them out of its feedback (control/notch_filter.hpp, in series per
// channel, on A z_true); by default there is none and the feedback is the plate's as above.
//
// read()/write()/truth() are real-time safe, like the twin's.
#include <array>
#include <string>

#include "piezoshift/control/notch_filter.hpp"
#include "piezoshift/control/signal_scaling.hpp"
#include "piezoshift/control/transmission_matrix.hpp"
#include "piezoshift/runtime/sim_backend.hpp"

namespace piezoshift::runtime {

class OracleBackend final : public DaqBackend {
 public:
  //! sim is not owned and must outlive this backend.
  //! sim is not owned and must outlive this backend. notches: none by default (mode_Hz 0).
  OracleBackend(SimBackend& sim, const control::TransmissionMatrix& matrix,
                const std::array<control::SignalScaling, control::kChannels>& scaling,
                const control::OracleNotches& notches = {}, double sample_time_s = 1e-3);

  void configure() override { sim_.configure(); }
  void activate() override { sim_.activate(); }
  void deactivate() noexcept override { sim_.deactivate(); }
  DaqStatus read(const CycleTime& t, Vec3& ai_V) noexcept override;
  DaqStatus write(const CycleTime& t, const Vec3& ao_V) noexcept override {
    return sim_.write(t, ao_V);
  }
  std::string name() const override { return "oracle"; }
  bool truth(Vec3& z_um, Vec3& interferometer_um) const noexcept override {
    return sim_.truth(z_um, interferometer_um);
  }
  double fringe_drift_nm() const noexcept override { return sim_.fringe_drift_nm(); }
  bool has_trigger_line() const noexcept override { return sim_.has_trigger_line(); }
  void stage_trigger_line(bool high) noexcept override { sim_.stage_trigger_line(high); }
  bool take_trigger_edge(TriggerEdge& edge) noexcept override {
    return sim_.take_trigger_edge(edge);
  }

 private:
  SimBackend& sim_;
  control::TransmissionMatrix matrix_;
  std::array<control::SignalScaling, control::kChannels> scaling_;
  std::array<std::array<control::NotchFilter, control::kMaxOracleNotches>, control::kChannels>
      notch_{};
};

}  // namespace piezoshift::runtime
