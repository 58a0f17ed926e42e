#pragma once
// The PSI acquisition sequence on a Stage (stage.hpp): for k = 0 .. N-1
//   move(k * step_nm);  wait_on_target(criterion);  poses_k = expose(exposure_s)
// with step_nm = lambda / 8 for pi/2 (lambda / 16 for the 13-frame's pi/4). Each frame records
// when it was commanded, when it came on target (or that it timed out) and its exposure's true
// pose trajectory; the stage keeps the tick-by-tick log.
#include <vector>

#include "piezoshift/core/wavelength.hpp"
#include "piezoshift/psi/stage.hpp"

namespace piezoshift::psi {

struct AcquisitionParams {
  int frames = 5;
  double step_nm = core::kHeNeWavelength_nm / 8.0;  //!< pi/2 at 632.8 nm
  OnTarget on_target{};
  double exposure_s = 1e-3;  //!< the camera's exposure
};

struct FrameRecord {
  double move_time_s = 0.0;
  double on_target_time_s = 0.0;
  bool on_target = false;
  double exposure_start_s = 0.0;
  std::vector<PoseSample> poses;  //!< the exposure's true pose trajectory
};

struct Acquisition {
  std::vector<FrameRecord> frames;
};

//! std::invalid_argument for frames < 3 or non-finite values.
Acquisition acquire(Stage& stage, const AcquisitionParams& params);

}  // namespace piezoshift::psi
