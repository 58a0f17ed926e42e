#include "piezoshift/instrument/measurement_lock.hpp"

#include <string>
#include <utility>

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

LockSetup measurement_lock_setup(psi::Mask mask, double pupil_radius_m,
                                 const plant::GeometryParams& geometry,
                                 const calibration::LoopCalibration& calibration, double retake_s,
                                 const SequenceParams& params, std::string_view option) {
  LockSetup l;
  l.lock = calibration.fringe_lock.value_or(control::FringeLockParams{});
  l.mask = std::move(mask);
  l.pupil_radius_m = pupil_radius_m;
  l.tripod.emplace(plant::make_twin_geometry(geometry).points);
  l.retake_s = retake_s;
  if (const std::string why = lock_problem(l, params); !why.empty())
    throw core::InputError(fmt::format("{}: {}", option, why));
  return l;
}

}  // namespace piezoshift::instrument
