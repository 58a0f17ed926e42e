#pragma once
// The fringe lock of a measurement on the twin's scene (`measure --lock`, Python's
// measure(lock=True); docs/fizeau.md): the lock needs the pupil before the first frame, which
// only a camera showing the twin's scene (the twin camera, Aravis's fake camera fed by the twin)
// has: its mask on the camera and its radius on the plate. P1..P3 are the twin's geometry's.
// Both front ends build the lock here, so they refuse the same values with the same words, and
// lock on the same requests: their flag, or a calibration file's [controller] outer = "fringes"
// with its [fringe_lock] parameters.
#include <optional>
#include <string>
#include <string_view>

#include "piezoshift/calibration/loop_calibration.hpp"
#include "piezoshift/camera/twin_camera.hpp"
#include "piezoshift/instrument/fringe_lock_session.hpp"
#include "piezoshift/instrument/sequence.hpp"
#include "piezoshift/plant/geometry.hpp"

namespace piezoshift::instrument {

//! Who asks a measurement for the fringe lock, as its refusals name it: the front end's flag
//! (flag_name) when it is set, else the calibration's `[controller] outer = "fringes"` (named
//! with its source); none when neither asks.
std::optional<std::string> lock_requested_by(bool flag, std::string_view flag_name,
                                             const calibration::LoopCalibration& calibration);

//! The lock of params on scene with the calibration's [fringe_lock] parameters (the lock's
//! defaults when it has none) and retake_s (LockSetup's other fields at their defaults).
//! core::InputError, its message prefixed with `option` (the front end's name for the lock), when
//! scene is nullptr (camera_spec names the camera) or lock_problem() refuses the lock.
LockSetup scene_lock_setup(const camera::TwinScene* scene, std::string_view camera_spec,
                           const plant::GeometryParams& geometry,
                           const calibration::LoopCalibration& calibration, double retake_s,
                           const SequenceParams& params, std::string_view option);

}  // namespace piezoshift::instrument
