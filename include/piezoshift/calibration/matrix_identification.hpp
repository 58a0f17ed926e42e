#pragma once
// Calibration stage 2 (paper, Section 3, second step): the motion transmission matrix A, with
// the PID loops working. Per repeat, per actuator i:
//   hold all three SGS targets at base_um; read the interferometer (static, 1 s) and the mean SGS
//   feedback -> (S0, Z0)
//   move actuator i alone to base_um + move_um; settle; read again -> (S1, Z1)
//   one pose: dS = S1 - S0, dZ = Z1 - Z0
// and A solves dS ~ A dZ over all poses by least squares (matrix_fit.hpp). Differencing against a
// reference read just before each move removes the interferometer's datum and most of the lab's
// slow drift. S is what the strain gauges read (mean feedback over the window), not the targets.
#include <vector>

#include "piezoshift/calibration/matrix_fit.hpp"
#include "piezoshift/rig/bench.hpp"
#include "piezoshift/rig/progress.hpp"

namespace piezoshift::calibration {

struct MatrixIdentificationOptions {
  double base_um = 2.0;   //!< common SGS target of the three actuators between moves
  double move_um = 7.0;   //!< the "certain displacement" of each actuator alone (base + move
                          //!< stays below the stroke a leg alone reaches while the other two
                          //!< hold the plate: 10 um saturates a stack on the twin)
  int repeats = 3;        //!< the paper: "repeated many times to attain average values"
  double settle_s = 0.5;  //!< after each move, before reading
};

struct MatrixIdentificationResult {
  MatrixFitResult fit;
  std::vector<control::Vec3> ds_um;  //!< one row per pose
  std::vector<control::Vec3> dz_um;
  double simulated_time_s = 0.0;
};

//! Runs the procedure on the bench (which must have its PID gains set); throws FitError when the
//! data cannot give A.
MatrixIdentificationResult identify_matrix(rig::Bench& bench,
                                           const MatrixIdentificationOptions& options = {},
                                           const rig::Progress& progress = {});

}  // namespace piezoshift::calibration
