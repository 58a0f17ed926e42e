#include "piezoshift/camera/make_camera.hpp"

#include <string>

#include <fmt/core.h>

#include "piezoshift/camera/aravis_camera.hpp"
#include "piezoshift/camera/files_camera.hpp"
#include "piezoshift/camera/twin_fed_camera.hpp"
#include "piezoshift/core/input_error.hpp"

namespace piezoshift::camera {

std::unique_ptr<Camera> make_camera(std::string_view spec, const CameraConfig& config,
                                    const TwinScene* twin) {
  if (std::string p = camera_config_problem(config); !p.empty())
    throw core::InputError(fmt::format("camera {}: {}", spec, p));
  std::unique_ptr<Camera> camera;
  // The twin camera on its scene, with the configuration's fringe loss.
  const auto twin_camera = [&] {
    TwinScene scene = *twin;
    scene.fringe_loss_start_s = config.fringe_loss_start_s;
    scene.fringe_loss_s = config.fringe_loss_s;
    return std::make_unique<TwinCamera>(std::move(scene), config.sensor);
  };
  if (spec == "twin") {
    if (twin == nullptr)
      throw core::InputError(
          "camera twin: no simulated interferometer to render (the twin "
          "camera needs the twin's surface: a measurement with --daq sim)");
    camera = twin_camera();
  } else if (spec.starts_with("files:")) {
    const std::string_view dir = spec.substr(6);
    if (dir.empty())
      throw core::InputError("camera files:: no directory after 'files:'");
    camera = std::make_unique<FilesCamera>(std::string(dir));
  } else if (spec.starts_with("aravis:Fake") && twin != nullptr) {
    // Aravis's in-process fake camera on the twin: shown the twin's fringes.
    camera = std::make_unique<TwinFedCamera>(twin_camera(),
                                             make_aravis_camera(std::string(spec.substr(7))));
  } else if (spec.starts_with("aravis:")) {
    camera = make_aravis_camera(std::string(spec.substr(7)));
  } else {
    throw core::InputError(
        fmt::format("camera '{}': not a camera (expected twin, files:DIR or aravis:ID)", spec));
  }
  camera->configure(config.settings);
  return camera;
}

}  // namespace piezoshift::camera
