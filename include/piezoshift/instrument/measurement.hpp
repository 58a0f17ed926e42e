#pragma once
// From a sequence's frames to the measurement: each average analysed on its own (analysis.hpp:
// the chosen algorithm, unwrapping, piston and tilt removed), the surfaces averaged pixel by
// pixel over the pixels valid in every average, then PV, RMS, PVr and the Zernike fit of the
// average. Beside it, the steps the stage really made, recovered from the fringes by AIA
// (phase_algorithms.hpp; the commanded steps as its start) on each average, and on the twin the
// true steps the exposures' mean piston made, 4 pi (piston_k - piston_0) / lambda.
#include <string>
#include <vector>

#include "piezoshift/instrument/sequence.hpp"
#include "piezoshift/psi/analysis.hpp"

namespace piezoshift::instrument {

struct MeasurementAnalysis {
  psi::Map surface_nm;  //!< the average of the averages' surfaces (NaN where any had none)
  psi::Mask valid;      //!< pixels valid in every average
  psi::SurfaceFigures figures;
  std::vector<double> zernike_nm;  //!< Noll j = 1.., of surface_nm
  std::vector<psi::SurfaceFigures> average_figures;
  //! Per average, per frame: steps recovered from the fringes (AIA), and on the twin the true
  //! ones; step_error_max_mrad is the largest |recovered - true| (0 without truth). An average
  //! whose AIA did not converge has no recovered steps (empty) and steps_reason says why: the
  //! steps are a check on the stage, the surface does not depend on them.
  std::vector<std::vector<double>> recovered_steps_rad;
  std::vector<std::vector<double>> true_steps_rad;
  double step_error_max_mrad = 0.0;
  std::string steps_reason;  //!< "" when every average's steps were recovered
  //! The worst step error as text: "0.77 mrad", or why there is none (no truth, not recovered).
  std::string step_error_text() const;
  //! Some average's steps were recovered and the truth is known.
  bool has_step_error() const;
  //! Whether the analysis' own fit converged on every average (aia, tilt-aia: psi's checks).
  bool converged = true;
  std::string reason;  //!< the first average whose fit did not converge, and why
};

//! The frames as counts, one Map each.
std::vector<psi::Map> frame_maps(const std::vector<camera::Frame>& frames);

//! Analyses a complete sequence (sequence.valid). std::invalid_argument when the frames carry no
//! fringes (analysis.hpp's check).
MeasurementAnalysis analyze_measurement(const SequenceResult& sequence,
                                        const SequenceParams& params, const psi::Mask& mask,
                                        const psi::AnalysisOptions& options);

}  // namespace piezoshift::instrument
