#pragma once
// The unit conversions at the controller's two edges, so the PID works in micrometres:
//   feedback_um = (sgs_V - sgs_offset_V) * sgs_um_per_V         SGS conditioner, 0..10 V
//   dac_V       = drive_offset_V + u_um * drive_V_per_um        DAQ output -> amplifier (x15)
//   u_um        = (dac_V - drive_offset_V) / drive_V_per_um     its inverse: the command that
//                                                               produced outputs already held
// Defaults: the conditioner spans the nominal stroke (16 um over 10 V, Table 1 and Section 4), and
// the drive maps the nominal free stroke to the DAQ's 10 V (150 V at the stack after the x15
// amplifier).
//
// Real-time safe: no heap, no exceptions, no I/O.
namespace piezoshift::control {

template <class T>
struct BasicSignalScaling {
  T sgs_um_per_V = T(1.6);      //!< 16 um nominal stroke over the conditioner's 10 V
  T sgs_offset_V = T(0.0);      //!< conditioner output at zero elongation
  T drive_V_per_um = T(0.625);  //!< 10 V DAQ (150 V stack) over 16 um nominal free stroke
  T drive_offset_V = T(0.0);    //!< DAQ volts at zero command

  constexpr T sgs_to_um(T sgs_V) const noexcept { return (sgs_V - sgs_offset_V) * sgs_um_per_V; }
  constexpr T um_to_dac(T u_um) const noexcept { return drive_offset_V + u_um * drive_V_per_um; }
  //! drive_V_per_um > 0 (control::params_problem, SafetySupervisor::configure).
  constexpr T dac_to_um(T dac_V) const noexcept {
    return (dac_V - drive_offset_V) / drive_V_per_um;
  }

  constexpr bool operator==(const BasicSignalScaling&) const noexcept = default;
};

using SignalScaling = BasicSignalScaling<double>;

template <class To, class From>
constexpr BasicSignalScaling<To> convert(const BasicSignalScaling<From>& s) noexcept {
  return {static_cast<To>(s.sgs_um_per_V), static_cast<To>(s.sgs_offset_V),
          static_cast<To>(s.drive_V_per_um), static_cast<To>(s.drive_offset_V)};
}

}  // namespace piezoshift::control
