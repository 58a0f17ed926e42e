// aravis:ID in a build without Aravis: the factory refuses with the reason, fake fills too.
#include "piezoshift/camera/aravis_camera.hpp"
#include "piezoshift/camera/aravis_fake_fill.hpp"
#include "piezoshift/core/input_error.hpp"

namespace piezoshift::camera {
namespace {
const char* const kWhy =
    "this piezoshift was built without Aravis (libaravis-dev; scripts/install-deps installs it)";
}

std::unique_ptr<Camera> make_aravis_camera(const std::string& id) {
  throw core::InputError("aravis:" + id + ": " + kWhy);
}

bool aravis_available() noexcept {
  return false;
}

void fake_fill_with(Camera& camera, FakeFill /*fill*/) {
  throw core::InputError(camera.name() + ": " + kWhy);
}

}  // namespace piezoshift::camera
