#pragma once
// The unit conversions at the controller's two edges, so the PID works in micrometres:
//   feedback_um = (sgs_V - sgs_offset_V) * sgs_um_per_V         SGS conditioner, 0..10 V
//   dac_V       = drive_offset_V + u_um * drive_V_per_um        DAQ output -> amplifier (x15)
// Defaults: the conditioner spans the nominal stroke (16 um over 10 V, Table 1 and Section 4), and
// the drive maps the nominal free stroke to the DAQ's 10 V (150 V at the stack after the x15
// amplifier).
//
// Real-time safe: no heap, no exceptions, no I/O.
namespace piezoshift::control {

struct SignalScaling {
  double sgs_um_per_V = 1.6;      //!< 16 um nominal stroke over the conditioner's 10 V
  double sgs_offset_V = 0.0;      //!< conditioner output at zero elongation
  double drive_V_per_um = 0.625;  //!< 10 V DAQ (150 V stack) over 16 um nominal free stroke
  double drive_offset_V = 0.0;    //!< DAQ volts at zero command

  constexpr double sgs_to_um(double sgs_V) const noexcept {
    return (sgs_V - sgs_offset_V) * sgs_um_per_V;
  }
  constexpr double um_to_dac(double u_um) const noexcept {
    return drive_offset_V + u_um * drive_V_per_um;
  }
};

}  // namespace piezoshift::control
