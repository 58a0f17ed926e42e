#pragma once
// Phase-step calibration from interferograms: the steps the stage really made, recovered by AIA
// (phase_algorithms.hpp) from one frame set, compared with the nominal steps k s (s the nominal
// step), as the controller calibration could use them:
//   delta_k = g s k + q (s k)^2 + e_k      least squares over k = 0 .. N-1
//   step_gain        g   (1 + the step gain error)
//   quadratic_per_rad q  (nonlinearity of the phase shifter over the sequence)
//   nonlinearity_pct = max_k |delta_k - g s k| / delta_{N-1} * 100 (deviation from the best line
//                      through the origin, as a percentage of the span)
//   steps_nm = delta_k lambda / (4 pi): the mirror motion (Fizeau in reflection)
// Written as a TOML table [psi_calibration] (format_step_calibration_toml; docs/psi.md).
#include <numbers>
#include <span>
#include <string>
#include <vector>
#include "piezoshift/core/wavelength.hpp"

namespace piezoshift::psi {

// The nominal steps calibrated: below 0.05 rad (2.5 nm of mirror motion at 632.8 nm) the frames
// of a set differ by a few % of their modulation, within a camera's noise; at pi they repeat in
// pairs (sin delta = 0) and the phase's sign is lost. 1e-300 rad used to give a NaN gain.
inline constexpr double kMinNominalStepRad = 0.05;
inline constexpr double kMaxNominalStepRad = std::numbers::pi - 0.05;

struct StepCalibration {
  std::string algorithm = "aia";
  double wavelength_nm = core::kHeNeWavelength_nm;
  double nominal_step_rad = 0.0;
  std::vector<double> steps_rad;      //!< delta_k, delta_0 = 0
  std::vector<double> steps_nm;       //!< the mirror's motion, delta_k lambda / (4 pi)
  std::vector<double> increments_nm;  //!< delta_k - delta_{k-1} in nm of mirror motion, k >= 1
  double step_gain = 1.0;
  double quadratic_per_rad = 0.0;
  double nonlinearity_pct = 0.0;
  double rms_step_error_rad = 0.0;  //!< RMS of delta_k - s k
  int iterations = 0;
  bool converged = true;
  std::string reason;  //!< the fit's own why-not (PhaseResult::reason), "" when it converged
};

//! std::invalid_argument for fewer than 3 steps or a nominal step outside
//! [kMinNominalStepRad, kMaxNominalStepRad].
StepCalibration calibrate_steps(std::span<const double> steps_rad, double nominal_step_rad,
                                double wavelength_nm);

//! Why c is not a calibration, "" when it is: the iteration that recovered the steps did not
//! converge (c.reason when the fit gave one), or a step or the step gain is not finite, or the gain
//! is not positive (the steps did not advance). A failure is a failure, never a number: such a c is
//! not written.
std::string step_calibration_problem(const StepCalibration& c);

std::string format_step_calibration_toml(const StepCalibration& c);

}  // namespace piezoshift::psi
