#pragma once
// What one phase-shifting measurement (measure_request.hpp) gave: how it ended, what ran, the
// sequence, its analysis and, on the twin camera, the figures against the truth. The CLI writes
// it into its folder and prints it, Python returns it as a dict, both through measure_json.
#include <cstdint>
#include <optional>
#include <string>

#include "piezoshift/instrument/measurement.hpp"
#include "piezoshift/instrument/sequence.hpp"
#include "piezoshift/psi/grid.hpp"

namespace piezoshift::procedures {

//! How a measurement ended. The CLI's exit status: 0 kMeasured; 3 kFault (the safety supervisor
//! latched); 4 the others (Python: ProcedureFailed).
enum class MeasureEnd : std::uint8_t {
  kMeasured,      //!< a valid sequence, its fits converged
  kFault,         //!< the sequence is not valid: the safety supervisor latched a fault
  kNotValid,      //!< not valid: a step that did not settle, a frame lost or late
  kNoPupil,       //!< no pupil in the frames (none given)
  kNoPhase,       //!< the analysis found no phase in the frames
  kNotConverged,  //!< the analysis ran, its fits did not converge
};

struct MeasureOutcome {
  MeasureEnd end = MeasureEnd::kMeasured;
  std::string reason;     //!< "" when measured, else why not, prefixed "measure: "
  std::string camera;     //!< the camera's name ("twin", "aravis:Fake_1", ...)
  std::string daq;        //!< the DAQ backend's name
  std::string algorithm;  //!< psi's name of the analysis' algorithm
  std::string calibration_source;
  double rate_Hz = 1000.0;
  bool real_time = true;
  instrument::SequenceParams params;
  instrument::SequenceResult sequence;
  //! The analysis (from kNoPhase on: kMeasured and kNotConverged have one).
  std::optional<instrument::MeasurementAnalysis> analysis;
  psi::Mask mask;                      //!< the pupil analysed (empty before the analysis)
  std::optional<psi::Map> truth_nm;    //!< the twin camera's surface (the scene's)
  std::optional<double> error_rms_nm;  //!< measured - truth, piston and tilt removed
  //! The same frames from an ideal stage (the camera's and the algorithm's floor, one average).
  std::optional<double> ideal_error_rms_nm;
  //! The same over the whole measurement, every exposure with its own frame's noise draws
  //! (twin camera): the floor the stage's error adds to.
  std::optional<double> floor_error_rms_nm;
  //! The surface's lateral scale, metres on the plate per pixel (instrument::plate_m_per_px of
  //! the mask and [camera] pupil_radius_m). 0: unknown.
  double m_per_px = 0.0;
};

//! What the stage added to the floor, in quadrature: sqrt(measured^2 - floor^2), 0 when the
//! measurement is at its floor [nm RMS].
double stage_error_rms_nm(double measured_rms_nm, double floor_rms_nm);

}  // namespace piezoshift::procedures
