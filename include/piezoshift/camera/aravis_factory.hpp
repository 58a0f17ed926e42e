#pragma once
// The hook for `aravis:ID` (a GenICam camera through libaravis). make_camera() calls this for
// every "aravis:" spec. Exactly one definition is linked into piezoshift_camera:
//   aravis_unavailable.cpp   (built when libaravis is not): refuses with core::InputError
//                            "camera aravis:ID: aravis cameras are not built in ..."
//   the Aravis backend's     (built when it is): opens the camera ID names ("" = the first one)
// src/camera/CMakeLists.txt chooses between them.
#include <memory>
#include <string>

#include "piezoshift/camera/camera.hpp"

namespace piezoshift::camera {

//! An unconfigured camera for ID (the text after "aravis:"); throws core::InputError naming the
//! camera when it cannot be opened.
std::unique_ptr<Camera> make_aravis_camera(const std::string& id);

}  // namespace piezoshift::camera
