#pragma once
// One actuator's calibration scan read from the Fizeau's fringes instead of the XL-80 (the
// first slice of "calibration from fringes"): the inner loops alone (DriveMode::kActuators,
// as the paper's calibration moves one actuator at a time), the camera exposing at each settled
// pose, psi::FringeTracker giving P1..P3 of every frame relative to the first.
//
//   reference: W frames of common SGS targets base_um + (k - W + 1) reference_step_um on all three
//              (lambda/8 of piston by default: the PSI-like first window the tracker needs,
//              >= 40 nm a step measured), ending at base_um on all three (the scan's start)
//   scan:      actuator `actuator` alone from base_um to base_um + move_um in n equal moves, n the
//              least for which the predicted largest step in the pupil (the leg's step carried
//              through the rigid plate to the pupil's edge) stays below max_pupil_step_nm
//   each pose: drive, run settle_s, trigger the camera, tick through its exposure feeding the
//              plate's true pose to it (the twin camera renders from it), wait for the frame,
//              push it to the tracker; at_pose (optional) is called with the bench still there
//
// It says when it cannot: a refused trigger, a lost or failed frame, a fault the supervisor
// latched, or a frame the tracker refused (after which the fringe order is lost) end the scan
// with valid = false and the first reason; the poses taken so far are kept.
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "piezoshift/camera/camera.hpp"
#include "piezoshift/core/wavelength.hpp"
#include "piezoshift/instrument/scan_stage.hpp"
#include "piezoshift/psi/fringe_tracker.hpp"
#include "piezoshift/psi/grid.hpp"
#include "piezoshift/rig/bench.hpp"
#include "piezoshift/rig/validity.hpp"

namespace piezoshift::instrument {

struct FringeActuatorScanParams {
  std::size_t actuator = 0;  //!< 0..2
  double base_um = 2.0;      //!< common SGS target at the scan's start (stage 2's base)
  double move_um = 7.0;      //!< the actuator alone, base_um -> base_um + move_um (stage 2's)
  int reference_frames = 5;  //!< the tracker's first window
  double wavelength_nm = core::kHeNeWavelength_nm;
  double reference_step_um =
      core::kHeNeWavelength_um / 8.0;  //!< lambda/8 of piston a reference frame
  //! The largest step a frame may make anywhere in the pupil, predicted from the commanded leg
  //! step: half the tracker's 0.75 pi limit (118.6 nm), a margin of 2 for what the prediction
  //! ignores (the gauges' gains, the plate's coupling of the legs, the PIDs' settling error).
  double max_pupil_step_nm = 0.5 * 0.75 * core::kHeNeWavelength_nm / 4.0;
  double settle_s = 0.1;               //!< after each move, before the exposure
  double initial_settle_s = 0.5;       //!< after the servo closes at the reference's first pose
  double pupil_radius_m = 0.025;       //!< the pupil on the plate (FizeauParams::pupil_radius_m)
  double frame_timeout_s = 5.0;        //!< wall time for a frame to arrive after its exposure
  psi::FringeTrackerParams tracker{};  //!< points and window are set from the twin and above
};

//! Why p cannot run ("" when it can), naming the field.
std::string fringe_actuator_scan_problem(const FringeActuatorScanParams& p);

struct FringeScanPose {
  std::size_t frame = 0;
  bool reference = false;           //!< one of the first window's frames
  control::Vec3 target_um{};        //!< S commanded (Z_d on a piston scan)
  std::uint8_t saturated_mask = 0;  //!< the PIDs at their limits when the exposure began
  control::Vec3 sgs_um{};           //!< mean SGS feedback over the exposure
  bool valid = false;               //!< the tracker resolved it (else points NaN, reason why)
  std::string reason;
  control::Vec3 points_um{};        //!< P1..P3 from the fringes, relative to frame 0
  bool has_truth = false;           //!< the stage is the twin's (else truth_points_um is 0)
  control::Vec3 truth_points_um{};  //!< the twin's P1..P3, mean over the exposure, from frame 0's
  double time_s = 0.0;              //!< loop time of the trigger
};

struct FringeActuatorScanResult {
  std::vector<FringeScanPose> poses;  //!< reference frames, then one per move (base included)
  std::size_t base_pose = 0;          //!< index of the scan's start (the reference's last frame)
  int moves = 0;
  double leg_step_um = 0.0;
  double predicted_pupil_step_nm = 0.0;  //!< the largest, per move
  double simulated_time_s = 0.0;         //!< bench time of the whole scan
  double wall_time_s = 0.0;
  double tracker_wall_s = 0.0;         //!< of which in the tracker
  psi::Mask pupil;                     //!< the pupil the tracker used (given, or found)
  bool pupil_from_modulation = false;  //!< found in the reference frames' modulation
  rig::Validity validity;
};

//! The largest step in a pupil of radius pupil_radius_m that a leg step of leg_um on actuator
//! i makes, through the rigid plate on legs at `actuators` [nm].
double pupil_step_nm(const std::array<kinematics::PlatePoint, 3>& actuators, std::size_t i,
                     double leg_um, double pupil_radius_m);

//! The tracker's plate_m_per_px for a pupil of radius pupil_radius_m on the plate imaged as mask
//! (its radius in pixels: psi::pupil_of). std::invalid_argument for an empty mask.
double plate_m_per_px(const psi::Mask& mask, double pupil_radius_m);

//! Stage 2's pose (matrix_identification.hpp) from a scan: its last pose against its base, dS
//! from the gauges over the two exposures, dZ from the fringes [um]. The three actuators' poses
//! give A through calibration::fit_transmission_matrix. std::invalid_argument for a scan that
//! is not valid or has no move.
struct ScanMatrixPose {
  control::Vec3 ds_um{};
  control::Vec3 dz_um{};
};
ScanMatrixPose matrix_pose(const FringeActuatorScanResult& scan);

//! Runs the scan (see the header) on the stage with the camera (configured, not started; its
//! size the mask's). An empty mask: the pupil is found in the reference frames' fringe
//! modulation (psi::pupil_from_modulation; none found, or fewer than 16 pixels, fails the scan),
//! its radius on the plate params.pupil_radius_m. Throws core::InputError for params
//! fringe_actuator_scan_problem() refuses and for a camera whose frame size is not the mask's.
FringeActuatorScanResult run_fringe_actuator_scan(
    ScanStage& stage, camera::Camera& camera, const psi::Mask& mask,
    const FringeActuatorScanParams& params,
    const std::function<void(const FringeScanPose&)>& at_pose = {});

//! The same on the twin's bench (BenchScanStage); at_pose gets the bench, still at the pose.
FringeActuatorScanResult run_fringe_actuator_scan(
    rig::Bench& bench, camera::Camera& camera, const psi::Mask& mask,
    const FringeActuatorScanParams& params,
    const std::function<void(rig::Bench&, const FringeScanPose&)>& at_pose = {});

}  // namespace piezoshift::instrument
