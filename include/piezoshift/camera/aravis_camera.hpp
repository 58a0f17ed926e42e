#pragma once
// A GenICam camera (GigE Vision or USB3 Vision) through Aravis 0.8: `aravis:ID` (docs/camera.md).
//
// ID is what arv_camera_new() accepts: the device id Aravis lists ("Basler-acA1300-21234567"), a
// serial number, an IP address, or "" for the first camera found. "Fake_1" is Aravis's in-process
// fake camera, "Aravis-Fake-<serial>" an arv-fake-gv-camera-0.8 on the network. An optional
// suffix "@Line1" picks the input line a line trigger listens on (default Line0).
//
// The Aravis types stay inside aravis_camera.cpp: nothing here needs glib, and a build without
// Aravis links (make_aravis_camera then refuses with the reason).
#include <memory>
#include <string>

#include "piezoshift/camera/camera.hpp"

namespace piezoshift::camera {

//! Opens nothing yet: configure() opens the device. Throws core::InputError when this build has
//! no Aravis (scripts/install-deps installs libaravis-dev).
std::unique_ptr<Camera> make_aravis_camera(const std::string& id);

//! True when this build links Aravis (tests skip without it).
bool aravis_available() noexcept;

}  // namespace piezoshift::camera
