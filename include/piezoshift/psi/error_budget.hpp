#pragma once
// Monte Carlo error budget of each phase algorithm: the surface RMS error (piston and tilt
// removed, against the known test surface) that one error source alone leaves, frames rendered
// by fizeau_simulation.hpp on a small pupil. Sources and their default magnitudes (stated so the
// table can be read against the stage's own figures):
//   none                 perfect steps, no noise (16-bit frames): the algorithm's floor
//   step gain            every step (1 + step_gain_error) times nominal (linear miscalibration)
//   step noise           each frame's piston off by N(0, step_noise_nm)
//   tilt per frame       each frame's theta_x, theta_y ~ N(0, tilt_per_frame_urad)
//   vibration            piston a sin(2 pi f t + random phase) during each exposure
//   intensity noise      additive Gaussian, intensity_noise times the mean level
//   quantisation         quantization_bits-bit camera, no other noise
// The result (mean over trials of the RMS error) is printed as a table: rows the sources,
// columns the algorithms (format_budget_table), and can be drawn with io::plot.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "piezoshift/core/wavelength.hpp"
#include "piezoshift/psi/phase_algorithms.hpp"

namespace piezoshift::psi {

struct BudgetParams {
  int size_px = 64;  //!< square camera; the pupil is 0.45 of it in radius
  int trials = 3;
  double wavelength_nm = core::kHeNeWavelength_nm;
  double pupil_radius_m = 0.025;
  double exposure_s = 1e-3;
  double step_gain_error = 0.02;
  double step_noise_nm = 1.0;
  double tilt_per_frame_urad = 0.05;  //!< 1.25 nm at a 25 mm pupil edge
  double vibration_nm = 2.0;
  double vibration_hz = 100.0;
  double intensity_noise = 0.01;
  int quantization_bits = 8;
  std::uint64_t seed = 1;
};

struct BudgetRow {
  std::string source;
  std::string magnitude;
  std::vector<double> rms_nm;  //!< one per algorithm
};

struct ErrorBudget {
  std::vector<Algorithm> algorithms;
  std::vector<BudgetRow> rows;
};

ErrorBudget error_budget(const BudgetParams& params, std::span<const Algorithm> algorithms);
std::string format_budget_table(const ErrorBudget& budget);

}  // namespace piezoshift::psi
