#pragma once
// The twin camera as `calibrate --interferometer fizeau --camera twin` sets it up: square frames
// (256 px by default) showing the default test surface drawn from seed, the Fizeau's optics at
// 632.8 nm, configured and not started.
#include <cstdint>

#include "piezoshift/camera/camera_config.hpp"
#include "piezoshift/camera/twin_camera.hpp"

namespace piezoshift::instrument {

struct TwinBenchCamera {
  explicit TwinBenchCamera(std::uint64_t seed, int size_px = 256)
      : settings(square(size_px)),
        scene(camera::make_twin_scene(
            psi::SurfaceSpec{},
            camera::measurement_optics(settings, camera::CameraConfig{}.pupil_radius_m, 632.8),
            seed)),
        cam(scene, psi::CameraParams{}) {
    cam.configure(settings);
  }

  camera::CameraSettings settings;
  camera::TwinScene scene;
  camera::TwinCamera cam;

 private:
  static camera::CameraSettings square(int size_px) {
    camera::CameraSettings s;
    s.width_px = s.height_px = size_px;
    return s;
  }
};

}  // namespace piezoshift::instrument
