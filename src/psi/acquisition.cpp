#include "piezoshift/psi/acquisition.hpp"

#include <cmath>
#include <stdexcept>

namespace piezoshift::psi {

Acquisition acquire(Stage& stage, const AcquisitionParams& p) {
  if (p.frames < 3 || p.frames > 64 || !std::isfinite(p.step_nm) || !(p.exposure_s > 0.0))
    throw std::invalid_argument("acquisition: frames 3..64, a finite step and a positive exposure");
  Acquisition a;
  for (int k = 0; k < p.frames; ++k) {
    FrameRecord f;
    f.move_time_s = stage.time_s();
    stage.move(k * p.step_nm);
    f.on_target = stage.wait_on_target(p.on_target);
    f.on_target_time_s = stage.time_s();
    f.exposure_start_s = stage.time_s();
    f.poses = stage.expose(p.exposure_s);
    a.frames.push_back(std::move(f));
  }
  return a;
}

}  // namespace piezoshift::psi
