#pragma once
// The whole simulated measurement, what `piezoshift psi simulate` runs:
//   1. a test surface (SurfaceSpec) on the camera's pupil;
//   2. the acquisition sequence (acquisition.hpp) on the simulated bench with the given
//      controller: N frames at the algorithm's nominal step, each exposure's TRUE plate motion;
//   3. each frame rendered from that motion (fizeau_simulation.hpp), camera noise included;
//   4. the same frames rendered with an ideal stage (exact nominal steps, no motion in the
//      exposure) and the same camera noise draws;
//   5. both analysed (analysis.hpp) and compared with the truth:
//        error_rms_nm        stage + camera + algorithm
//        ideal_error_rms_nm  camera + algorithm
//        stage_error_rms_nm  sqrt(error^2 - ideal^2) (0 when negative): what the stage causes.
#include <cstdint>
#include <vector>

#include "piezoshift/config/project_config.hpp"
#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/psi/acquisition.hpp"
#include "piezoshift/psi/analysis.hpp"
#include "piezoshift/psi/fizeau_simulation.hpp"

namespace piezoshift::psi {

struct SimulationParams {
  FizeauParams fizeau{};
  CameraParams camera{};
  SurfaceSpec surface{};
  Algorithm algorithm = Algorithm::kHariharan5;
  int frames = 0;  //!< 0: the algorithm's count (5 for lsq, aia, tilt-aia)
  OnTarget on_target{};
  double base_um = 5.0;  //!< the reference position on the stage's travel
  std::uint64_t seed = 1;
};

struct FrameStats {
  double step_nm = 0.0;    //!< mean piston during the exposure minus frame 0's
  double blur_nm = 0.0;    //!< piston range during the exposure
  double tip_urad = 0.0;   //!< mean theta_x minus frame 0's
  double tilt_urad = 0.0;  //!< mean theta_y minus frame 0's
  double settle_s = 0.0;   //!< from the move to on target
  bool on_target = false;
};

struct SimulationResult {
  Mask mask;
  Map truth_nm;
  std::vector<Map> frames;        //!< counts
  std::vector<Map> ideal_frames;  //!< counts, ideal stage
  Acquisition acquisition;
  std::vector<StageLogEntry> log;
  std::vector<FrameStats> frame_stats;
  Analysis analysis;
  Analysis ideal;
  double error_rms_nm = 0.0;
  double ideal_error_rms_nm = 0.0;
  double stage_error_rms_nm = 0.0;
};

//! Throws core::InputError for parameters out of range (naming the field).
SimulationResult simulate_psi(const config::ProjectConfig& config,
                              const control::SemiClosedLoopParams& controller,
                              const SimulationParams& params);

}  // namespace piezoshift::psi
