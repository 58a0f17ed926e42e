#include "piezoshift/instrument/scene_lock.hpp"

#include <string>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"

namespace piezoshift::instrument {

std::optional<std::string> lock_requested_by(bool flag, std::string_view flag_name,
                                             const calibration::LoopCalibration& calibration) {
  if (flag)
    return std::string(flag_name);
  if (calibration.fringe_lock)
    return fmt::format("{}: [controller] outer = \"fringes\"", calibration.source);
  return std::nullopt;
}

LockSetup scene_lock_setup(const camera::TwinScene* scene, std::string_view camera_spec,
                           const plant::GeometryParams& geometry,
                           const calibration::LoopCalibration& calibration, double retake_s,
                           const SequenceParams& params, std::string_view option) {
  if (scene == nullptr)
    throw core::InputError(
        fmt::format("{}: the lock needs the pupil on the camera before the sequence; with camera "
                    "{} that is not built yet (camera twin has it)",
                    option, camera_spec));
  LockSetup l;
  l.lock = calibration.fringe_lock.value_or(control::FringeLockParams{});
  l.mask = scene->mask;
  l.pupil_radius_m = scene->fizeau.pupil_radius_m;
  l.tripod.emplace(plant::make_twin_geometry(geometry).points);
  l.retake_s = retake_s;
  if (const std::string why = lock_problem(l, params); !why.empty())
    throw core::InputError(fmt::format("{}: {}", option, why));
  return l;
}

}  // namespace piezoshift::instrument
