#pragma once
// The paper's calibration (Section 3) on a bench with a single-beam interferometer (an XL-80 sees
// one point at a time): the procedure of matrix_identification.hpp and
// polynomial_identification.hpp organised per position of the optics, the stage held by the one
// control tick (guided_rig.hpp), each reading from an InterferometerSource.
//   stage 1  the PID gains: the base controller's (the paper's); a gain search needs the plate's
//            motion between the ticks, which a bench does not see
//   stage 2  for the optics at P1, then P2, then P3: per repeat and per actuator i, hold all
//            SGS targets at base_um, settle, read; move actuator i alone by move_um, settle, read.
//            A pose (dS, dZ): dZ_j from the session at P_j, dS the mean over the three sessions
//            of the SGS differences; A solves dS ~ A dZ (matrix_fit.hpp)
//   stage 3  the optics at the centroid of P1..P3 (the plate's mean displacement), interferometer
//            zeroed with the stage at rest: for each command c_k, Z_d = c_k, settle, read m_k;
//            a command at which a PID sits at its limit is skipped; p fits c ~ p(m) (poly_fit.hpp)
// On the twin (BenchRig, stage 2 on seed + 1, stage 3 on seed + 2) the session at P1 drives
// exactly what `calibrate` on the twin drives, so A and p agree with it to the noise.
//
// Plausibility, before a reading enters the session (a refused reading is asked again at the
// prompt, an error otherwise):
//   stage 2 base    |reading - previous base reading at that point| <= max_zero_drift_um
//   stage 2 moved   |dZ_j - (A0^-1 dS)_j| <= pose_tolerance_fraction move_um + 0.05 um, A0 the
//                   base controller's A (the paper's): catches a wrong sign, nm typed for um, the
//                   optics at the wrong point
//   stage 3         |m_k - c_k| <= level_tolerance_fraction c_k + 0.3 um, and m_k above the last
//                   reading (the stage moves up)
// Resuming: the session's readings are kept (a stage-2 base reading without its moved reading is
// dropped: the pose is a pair); a rig that replays() re-drives them, hardware goes on from the
// next step.
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "piezoshift/calibration/guided_session.hpp"
#include "piezoshift/calibration/interferometer_source.hpp"
#include "piezoshift/calibration/matrix_identification.hpp"
#include "piezoshift/calibration/polynomial_identification.hpp"
#include "piezoshift/rig/guided_rig.hpp"

namespace piezoshift::calibration {

using control::Vec3;

struct GuidedOptions {
  MatrixIdentificationOptions matrix{};
  PolynomialIdentificationOptions polynomial{};
  double max_zero_drift_um = 0.05;
  double pose_tolerance_fraction = 0.1;
  double level_tolerance_fraction = 0.1;
};

struct GuidedStep {
  int stage = 2;  //!< 2 (matrix A) or 3 (polynomial p)
  Optics optics = Optics::kP1;
  int repeat = 0;            //!< stage 2
  std::size_t actuator = 0;  //!< stage 2: 0..2
  bool moved = false;        //!< stage 2: false the base pose, true actuator moved
  double command_um = 0.0;   //!< stage 3
  Vec3 setpoint_um{};        //!< S (stage 2) or Z_d (stage 3)
};

//! The steps in order: stage 2 (3 points x repeats x 3 actuators x 2 poses), then stage 3.
std::vector<GuidedStep> guided_plan(const GuidedOptions& options);
//! The pose in words, for the operator.
std::string describe(const GuidedStep& step, const GuidedOptions& options);

struct GuidedIo {
  InterferometerSource& source;
  std::function<void(const std::string&)> say;       //!< instructions, to the operator
  std::function<void(const GuidedSession&)> record;  //!< after every reading
};

struct GuidedOutcome {
  bool complete = false;  //!< false: the source ended; the session holds what was taken
  std::size_t taken = 0;  //!< readings taken in this run
  control::SemiClosedLoopParams controller;  //!< base with the fitted A and p (when complete)
  MatrixIdentificationResult matrix;
  PolynomialIdentificationResult polynomial;
};

//! Runs the plan, resuming session. Throws rig::ProcedureFailed when a rig's supervisor
//! trips, core::InputError for a refused reading from a source that cannot retry, FitError when
//! the data cannot give A or p. stage2 and stage3 may be the same rig (hardware).
GuidedOutcome run_guided_calibration(rig::GuidedRig& stage2, rig::GuidedRig& stage3,
                                     const control::SemiClosedLoopParams& base,
                                     GuidedSession& session, GuidedIo& io,
                                     const GuidedOptions& options = {});

}  // namespace piezoshift::calibration
