#pragma once
// A camera from its command-line spec, configured with the [camera] section's settings:
//
//   "twin"        TwinCamera of the scene (the Fizeau simulation; a measurement on the twin
//                 supplies the surface, mask, optics and seed) with config's sensor model
//   "files:DIR"   FilesCamera replaying DIR's PNG files
//   "aravis:ID"   make_aravis_camera(ID) (aravis_camera.hpp), refused where it is not built in;
//                 "aravis:Fake..." with a scene: Aravis's in-process fake camera shown the
//                 twin's fringes (twin_fed_camera.hpp)
//
// Anything else is core::InputError naming the spec and the choices. The camera returned has had
// configure(config.settings) (so a size, pixel format or file it cannot take is refused here);
// the caller calls start().
#include <memory>
#include <string_view>

#include "piezoshift/camera/camera.hpp"
#include "piezoshift/camera/camera_config.hpp"
#include "piezoshift/camera/twin_camera.hpp"

namespace piezoshift::camera {

//! twin: the scene for "twin" and for a fake Aravis camera on the twin (nullptr refuses "twin":
//! nothing to render).
std::unique_ptr<Camera> make_camera(std::string_view spec, const CameraConfig& config,
                                    const TwinScene* twin = nullptr);

}  // namespace piezoshift::camera
