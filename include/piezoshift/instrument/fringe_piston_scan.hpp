#pragma once
// Calibration stage 3's motion read from the Fizeau's fringes instead of the XL-80:
// the full controller (drive_points, with the gains and A found and p the identity, as stage 3
// runs) moves the three points together from 0 to max_um, the camera exposing at each settled
// pose and psi::FringeTracker giving P1..P3 of every frame relative to the first.
//
//   reference: W frames at Z_d = k reference_step_um (k = 0..W-1) on all three points: the
//              PSI-like first window the tracker needs (lambda/8 of piston a step by default)
//   scan:      on from the reference's last pose to max_um in n equal moves, n the least for
//              which a move stays below max_pupil_step_nm (a common move is piston: its step in
//              the pupil is the move itself, the tilt A's error leaves is far below the margin)
//   each pose: as the actuator scan's (fringe_actuator_scan.hpp): drive, settle, expose, track
//
// Every frame is a stage-3 point: the command Z_d and the mean of the three points' fringe
// displacements. Their datum is frame 0's, at Z_d = 0: the stage from rest with the loop closed
// at zero. On the twin the PIDs sit at their lower limit there (the gauges' zero is a few nm
// below the stacks' 0 V position, docs/calibration.md), so frame 0 is the plate at rest, the
// pose at which the XL-80's datum is set (the twin's start). A pose at which a PID sat at its
// limit is kept in the scan (the fringes still follow the plate) and left out of the fit by the
// caller, as stage 3 leaves it out.
// It says when it cannot, as the actuator scan does: valid = false and the first reason.
#include <string>
#include <vector>

#include "piezoshift/camera/camera.hpp"
#include "piezoshift/core/wavelength.hpp"
#include "piezoshift/instrument/fringe_actuator_scan.hpp"
#include "piezoshift/psi/grid.hpp"
#include "piezoshift/rig/bench.hpp"
#include "piezoshift/rig/validity.hpp"

namespace piezoshift::instrument {

struct FringePistonScanParams {
  double max_um = 11.0;      //!< stage 3's span (PolynomialIdentificationOptions::max_um)
  int reference_frames = 5;  //!< the tracker's first window
  double wavelength_nm = core::kHeNeWavelength_nm;
  double reference_step_um =
      core::kHeNeWavelength_um / 8.0;  //!< lambda/8 of piston a reference frame
  //! The largest move between frames: half the tracker's 118.6 nm (fringe_actuator_scan.hpp)
  double max_pupil_step_nm = 0.5 * 0.75 * core::kHeNeWavelength_nm / 4.0;
  double settle_s = 0.1;               //!< after each move, before the exposure
  double initial_settle_s = 0.5;       //!< after the servo closes at Z_d = 0
  double frame_timeout_s = 5.0;        //!< wall time for a frame to arrive after its exposure
  double pupil_radius_m = 0.025;       //!< the pupil on the plate, for a pupil found in frames
  psi::FringeTrackerParams tracker{};  //!< points and window are set from the stage and above
};

//! Why p cannot run ("" when it can), naming the field.
std::string fringe_piston_scan_problem(const FringePistonScanParams& p);

struct FringePistonScanResult {
  std::vector<FringeScanPose> poses;  //!< one per frame, reference included; target_um = Z_d
  int moves = 0;                      //!< after the reference
  double step_um = 0.0;               //!< of each of those moves
  double simulated_time_s = 0.0;
  double wall_time_s = 0.0;
  double tracker_wall_s = 0.0;
  psi::Mask pupil;  //!< the pupil the tracker used (given, or found)
  rig::Validity validity;
};

//! Runs the scan on the stage (its controller carrying the gains and A; the caller sets p to
//! the identity) with the camera (configured, not started; its size the mask's, or an empty mask
//! for a pupil found in the reference frames, as the actuator scan's). Throws core::InputError
//! for params fringe_piston_scan_problem() refuses and for a camera whose frame size is not the
//! mask's.
FringePistonScanResult run_fringe_piston_scan(ScanStage& stage, camera::Camera& camera,
                                              const psi::Mask& mask,
                                              const FringePistonScanParams& params);

//! The same on the twin's bench (BenchScanStage).
FringePistonScanResult run_fringe_piston_scan(rig::Bench& bench, camera::Camera& camera,
                                              const psi::Mask& mask,
                                              const FringePistonScanParams& params);

}  // namespace piezoshift::instrument
