#pragma once
// The paper's three calibration stages (calibration/calibration_procedure.hpp) with the Fizeau's
// fringes as the interferometer instead of the XL-80 ("calibration from fringes", docs/fizeau.md;
// `piezoshift calibrate --interferometer fizeau --camera twin`):
//   1. PID gains  calibration::tune_pid, unchanged: it reads the gauges, no interferometer
//   2. matrix A   one fringe actuator scan per actuator (fringe_actuator_scan.hpp) on one
//                 bench: each scan's last pose against its base is one of stage 2's poses (dS
//                 from the gauges over the exposure, dZ from the fringes), A by least squares
//                 (calibration::fit_transmission_matrix) over the three
//   3. cubic p    one fringe piston scan (fringe_piston_scan.hpp) with the gains and A in place:
//                 every frame is a point (Z_d, the mean of P1..P3 from the fringes, on the
//                 gauges' reading of frame 0 as the datum), p by
//                 calibration::fit_cubic_polynomial, the poses with a PID at its limit left out
// Each stage on its own fresh bench (seed, seed + 1, seed + 2), as calibrate() does, or all on
// one ScanStage the caller holds (the real-time loop, scan_stage.hpp); the camera is the
// caller's, reused by every scan. No optics are moved: the camera sees P1..P3 at once in every
// frame.
// It says when it cannot: a scan that fails (a frame lost, the fringes lost, a fault latched)
// or a fit the data cannot give ends it with valid = false and the first reason, naming the
// stage; the controller is then not to be used.
#include <array>
#include <cstdint>

#include "piezoshift/calibration/calibration_procedure.hpp"
#include "piezoshift/camera/camera.hpp"
#include "piezoshift/camera/instrument_config.hpp"
#include "piezoshift/camera/twin_camera.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/core/wavelength.hpp"
#include "piezoshift/instrument/fringe_actuator_scan.hpp"
#include "piezoshift/instrument/fringe_piston_scan.hpp"
#include "piezoshift/instrument/scan_stage.hpp"
#include "piezoshift/psi/fizeau_simulation.hpp"
#include "piezoshift/psi/grid.hpp"
#include "piezoshift/rig/progress.hpp"
#include "piezoshift/rig/validity.hpp"

namespace piezoshift::instrument {

//! Where the camera's pupil is on the plate.
struct FringeOptics {
  psi::Mask mask;                         //!< the pupil on the camera (its frames' size)
  double pupil_radius_m = 0.025;          //!< FizeauParams::pupil_radius_m
  double plate_m_per_px = 0.025 / 120.0;  //!< pupil_radius_m / FizeauParams::pupil_radius_px
};

//! The twin camera's: its scene's mask and Fizeau optics.
FringeOptics twin_optics(const camera::TwinScene& scene);

struct FringeCalibrationOptions {
  //! Stage 1's choice and grid, the supervisor's limits, stage 2's base and move and stage 3's
  //! span (matrix.base_um, matrix.move_um, polynomial.max_um); the XL-80's repeats, settles and
  //! point count are not used (each scan is one pass, its settle is settle_s).
  calibration::CalibrationOptions stages{};
  double settle_s = 0.1;  //!< after each move, before the exposure (the scans' default)
  //! The largest step a frame may make in the pupil: half the tracker's limit (the scans')
  double max_pupil_step_nm = 0.5 * 0.75 * core::kHeNeWavelength_nm / 4.0;
  double wavelength_nm = core::kHeNeWavelength_nm;
};

struct FringeCalibrationOutcome {
  control::SemiClosedLoopParams controller;  //!< gains, A and p found (only if validity.valid)
  calibration::PidTuningResult pid;
  calibration::MatrixIdentificationResult matrix;          //!< ds/dz: the three scans' ends
  calibration::PolynomialIdentificationResult polynomial;  //!< command/measured: every frame
  std::array<FringeActuatorScanResult, 3> actuator_scans;
  FringePistonScanResult piston_scan;
  //! The pupil was found in the first scan's reference frames (FringeOptics::mask empty)
  bool pupil_from_modulation = false;
  //! Bench time of stages 2 and 3 (the scans): what the XL-80's stages 2 and 3 take otherwise
  double stage2_simulated_s = 0.0;
  double stage3_simulated_s = 0.0;
  //! Stage 3's datum: frame 0's mean displacement of P1..P3 as the gauges read it (through A),
  //! added to every frame's from the fringes [um]
  double stage3_datum_um = 0.0;
  double wall_time_s = 0.0;
  rig::Validity validity;
};

//! base supplies the sample time, limits and scaling; its gains, A and p are replaced. camera:
//! configured, not started, its frames the mask's size (else core::InputError).
FringeCalibrationOutcome calibrate_from_fringes(const config::ProjectConfig& config,
                                                const control::SemiClosedLoopParams& base,
                                                std::uint64_t seed, camera::Camera& camera,
                                                const FringeOptics& optics,
                                                const FringeCalibrationOptions& options = {},
                                                const rig::Progress& progress = {});

//! The same on a stage the caller holds (the real-time loop: LoopScanStage, loop_scan_stage.hpp),
//! for any camera: stage 1 keeps the stage's controller's gains (the paper's: the gain search
//! scores the plate between the ticks, which only the twin shows, as the guided calibration's),
//! stages 2 and 3 run on it one after the other. optics.mask empty: the pupil is found in the
//! first scan's reference frames' modulation and kept for the scans after it, its radius on the
//! plate optics.pupil_radius_m. The stage ends holding the last pose (A found, p the identity).
FringeCalibrationOutcome calibrate_from_fringes(ScanStage& stage, camera::Camera& camera,
                                                const FringeOptics& optics,
                                                const FringeCalibrationOptions& options = {},
                                                const rig::Progress& progress = {});

//! The options `calibrate --interferometer fizeau` and Python's calibrate_from_fringes() run
//! with: stage 1 (which reads no interferometer) keeps the paper's gains, scored alone, or
//! searches the grid (search_gains); the supervisor's limits are the installation's.
FringeCalibrationOptions fringe_calibration_options(bool search_gains,
                                                    const runtime::SafetyLimits& limits);

//! Frames the scans read (the three actuator scans' and the piston scan's).
std::size_t frames_read(const FringeCalibrationOutcome& r);

//! The same on the twin's bench with the twin camera, as `calibrate --interferometer fizeau
//! --camera twin` and Python's calibrate_from_fringes() run it: the camera on config's settings
//! showing surface drawn from seed, the controller at the twin DAQ's rate.
FringeCalibrationOutcome calibrate_twin_from_fringes(const camera::InstrumentConfig& config,
                                                     std::uint64_t seed,
                                                     const psi::SurfaceSpec& surface,
                                                     const FringeCalibrationOptions& options,
                                                     const rig::Progress& progress = {});

}  // namespace piezoshift::instrument
