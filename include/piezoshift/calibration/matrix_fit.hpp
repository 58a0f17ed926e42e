#pragma once
// Least-squares identification of the motion transmission matrix A of the paper's second Eq. 8,
//   S = A Z          S: actuator displacements (strain-gauge sensors) [um]
//                    Z: displacements of the measurement points P1..P3 (interferometer) [um]
// from n recorded poses (paper, Section 3, second step: move the actuators, record S and Z).
// Each pose is a row; stacking them gives
//   S (n x 3) = Z (n x 3) A^T   =>   A^T = argmin ||Z X - S||_F,
// solved with Eigen's JacobiSVD (three independent least-squares problems, one per actuator,
// sharing the design matrix Z).
//
// At least 3 poses: every row of A has 3 unknowns and each pose gives one equation for it, so
// three poses with independent Z determine A exactly (zero residual, nothing to judge it by);
// more poses average out measurement noise and make the residual meaningful. The design is
// rank-deficient (FitError) when sigma_min(Z) <= kRankRelTol * sigma_max(Z), e.g. when the three
// points never move independently.
//
// Outputs: residual rms per actuator r_j = sqrt(sum_i (S - Z A^T)_ij^2 / n), overall rms
// sqrt(sum_ij (...)^2 / (3 n)), cond(A) = sigma_max(A) / sigma_min(A) (+inf for a singular A),
// cond(Z) likewise: the sensitivity of A to noise in the data.
#include <array>
#include <cstddef>
#include <span>

#include "piezoshift/calibration/fit_error.hpp"
#include "piezoshift/control/transmission_matrix.hpp"
#include "piezoshift/control/vec3.hpp"

namespace piezoshift::calibration {

struct MatrixFitResult {
  control::TransmissionMatrix a;                  //!< S = A Z [um/um]
  std::array<double, 3> rms_residual_per_s_um{};  //!< r_j for S1, S2, S3 [um]
  double rms_residual_um = 0.0;                   //!< over all 3 n residuals [um]
  double condition_number = 0.0;                  //!< cond(A) [-]
  double design_condition_number = 0.0;           //!< cond(Z) [-]
  std::size_t poses = 0;
};

inline constexpr std::size_t kMatrixFitMinPoses = 3;

//! Fits A to poses (s_um[i], z_um[i]). Throws FitError for mismatched sizes, fewer than 3
//! poses, a non-finite value (naming the pose, 0-based) or a rank-deficient Z.
MatrixFitResult fit_transmission_matrix(std::span<const control::Vec3> s_um,
                                        std::span<const control::Vec3> z_um,
                                        double rank_rel_tol = kRankRelTol);

}  // namespace piezoshift::calibration
