#pragma once
// The fringe lock of a measurement (`measure --lock`, Python's measure(lock=True);
// docs/fizeau.md): the pupil on the camera is the one the front end knows (the twin camera's
// scene's mask, a mask file), else found from the lock's reference frames' modulation (any
// camera; the session does it); its radius on the plate is the camera config's. P1..P3 are the
// twin's geometry's (on a real stage: its drawing's, docs/fizeau.md).
// Both front ends build the lock here, so they refuse the same values with the same words, and
// lock on the same requests: their flag, or a calibration file's [controller] outer = "fringes"
// with its [fringe_lock] parameters.
#include <optional>
#include <string>
#include <string_view>

#include "piezoshift/calibration/loop_calibration.hpp"
#include "piezoshift/instrument/fringe_lock_session.hpp"
#include "piezoshift/instrument/sequence.hpp"
#include "piezoshift/plant/geometry.hpp"

namespace piezoshift::instrument {

//! Who asks a measurement for the fringe lock, as its refusals name it: the front end's flag
//! (flag_name) when it is set, else the calibration's `[controller] outer = "fringes"` (named
//! with its source); none when neither asks.
std::optional<std::string> lock_requested_by(bool flag, std::string_view flag_name,
                                             const calibration::LoopCalibration& calibration);

//! The lock of params with the calibration's [fringe_lock] parameters (the lock's defaults when
//! it has none) and retake_s (LockSetup's other fields at their defaults); the pupil: mask on the
//! camera (empty: the session finds it) and pupil_radius_m on the plate. core::InputError, its
//! message prefixed with `option` (the front end's name for the lock), when lock_problem()
//! refuses the lock.
LockSetup measurement_lock_setup(psi::Mask mask, double pupil_radius_m,
                                 const plant::GeometryParams& geometry,
                                 const calibration::LoopCalibration& calibration, double retake_s,
                                 const SequenceParams& params, std::string_view option);

}  // namespace piezoshift::instrument
