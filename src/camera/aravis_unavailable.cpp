// make_aravis_camera() for a build without libaravis (aravis_factory.hpp).
#include <fmt/core.h>

#include "piezoshift/camera/aravis_factory.hpp"
#include "piezoshift/core/input_error.hpp"

namespace piezoshift::camera {

std::unique_ptr<Camera> make_aravis_camera(const std::string& id) {
  throw core::InputError(fmt::format(
      "camera aravis:{}: aravis cameras are not built in (this piezoshift was built without "
      "libaravis; docs/camera.md)",
      id));
}

}  // namespace piezoshift::camera
