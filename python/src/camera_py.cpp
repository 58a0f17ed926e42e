// Python bindings of the camera module (docs/camera.md): the [camera] section (CameraSettings,
// the twin's sensor CameraParams, CameraConfig), the twin camera's scene (TwinScene,
// make_twin_scene) and any camera from its spec (make_camera: twin, files:DIR, aravis:ID) with
// its lifecycle. A frame's counts are a (height, width) uint16 numpy array; poll() and wait()
// return (FrameStatus, Frame or None), so a lost frame or a timeout is a status the caller sees,
// never a frame skipped.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <optional>
#include <string>

#include "bindings.hpp"
#include "images.hpp"
#include "piezoshift/camera/aravis_camera.hpp"
#include "piezoshift/camera/camera.hpp"
#include "piezoshift/camera/camera_config.hpp"
#include "piezoshift/camera/instrument_config.hpp"
#include "piezoshift/camera/make_camera.hpp"
#include "piezoshift/camera/twin_camera.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/core/wavelength.hpp"
#include "values.hpp"

namespace piezoshift::python {

namespace {

namespace cam = ps::camera;

void bind_camera_enums(py::module_& m) {
  py::enum_<cam::PixelFormat>(m, "PixelFormat")
      .value("MONO8", cam::PixelFormat::kMono8)
      .value("MONO12", cam::PixelFormat::kMono12)
      .value("MONO16", cam::PixelFormat::kMono16);
  m.def("bit_depth", &cam::bit_depth, py::arg("format"), "8, 12 or 16");
  py::enum_<cam::TriggerSource>(m, "TriggerSource")
      .value("SOFTWARE", cam::TriggerSource::kSoftware)
      .value("LINE", cam::TriggerSource::kLine);
  py::enum_<cam::FrameStatus>(m, "FrameStatus")
      .value("OK", cam::FrameStatus::kOk)
      .value("NONE", cam::FrameStatus::kNone)
      .value("TIMEOUT", cam::FrameStatus::kTimeout)
      .value("LOST", cam::FrameStatus::kLost)
      .value("ERROR", cam::FrameStatus::kError);
}

// The [camera] section: what a measurement asks of the camera, and the twin's sensor.
void bind_camera_config(py::module_& m) {
  using S = cam::CameraSettings;
  py::class_<S>(m, "CameraSettings")
      .def(py::init<>())
      .PS_RW(S, width_px)
      .PS_RW(S, height_px)
      .PS_RW(S, format)
      .PS_RW(S, exposure_s)
      .PS_RW(S, gain_dB)
      .PS_RW(S, trigger)
      .PS_RW(S, readout_s)
      .PS_RW(S, buffer_count);
  using P = ps::psi::CameraParams;
  py::class_<P>(m, "CameraParams")
      .def(py::init<>())
      .PS_RW(P, exposure_s)
      .PS_RW(P, full_well_e)
      .PS_RW(P, mean_fill)
      .PS_RW(P, visibility)
      .PS_RW(P, read_noise_e)
      .PS_RW(P, shot_noise)
      .PS_RW(P, bit_depth);
  using C = cam::CameraConfig;
  py::class_<C>(m, "CameraConfig")
      .def(py::init<>())
      .PS_RW(C, settings)
      .PS_RW(C, sensor)
      .def("problem", &cam::camera_config_problem,
           "The first value outside its range, or '' when every one is valid");
  m.def(
      "load_camera_config",
      [](const std::string& path) { return cam::load_instrument_config(path).camera; },
      py::arg("path"),
      "The [camera] section of a configuration file, read as `piezoshift measure --config` reads "
      "the file (every section checked, unknown keys refused with InputError)");
}

void bind_twin_scene(py::module_& m) {
  using F = ps::psi::FizeauParams;
  py::class_<F>(m, "FizeauParams")
      .def(py::init<>())
      .PS_RW(F, width_px)
      .PS_RW(F, height_px)
      .PS_RW(F, pupil_radius_px)
      .PS_RW(F, pupil_radius_m)
      .PS_RW(F, wavelength_nm)
      .PS_RW(F, subsamples);
  using T = cam::TwinScene;
  py::class_<T>(m, "TwinScene")
      .def_property_readonly("surface_nm", [](const T& s) { return map_to_numpy(s.surface_nm); })
      .def_property_readonly("mask", [](const T& s) { return mask_to_numpy(s.mask); })
      .PS_RO(T, fizeau)
      .PS_RO(T, seed)
      .PS_RO(T, max_tick_rate_Hz);
  m.def(
      "make_twin_scene",
      [](const std::string& surface, const std::optional<cam::CameraConfig>& config,
         std::uint64_t seed, const std::optional<ps::psi::FizeauParams>& fizeau) {
        if (config && fizeau)
          throw ps::core::InputError("make_twin_scene: give config or fizeau, not both");
        const ps::psi::SurfaceSpec spec =
            surface.empty() ? ps::psi::SurfaceSpec{} : ps::psi::parse_surface_spec(surface);
        const cam::CameraConfig cc = config.value_or(cam::CameraConfig{});
        return cam::make_twin_scene(
            spec,
            fizeau.value_or(cam::measurement_optics(cc.settings, cc.pupil_radius_m,
                                                    ps::core::kHeNeWavelength_nm)),
            seed);
      },
      py::arg("surface") = "", py::arg("config") = py::none(), py::arg("seed") = 1,
      py::arg("fizeau") = py::none(),
      "The twin camera's scene: the surface ('Z4=40,rough=0.5' as `psi simulate` takes it; '' "
      "its default) drawn from seed on the optics `measure` uses for config's frame size, or on "
      "fizeau's");
}

void bind_frame(py::module_& m) {
  using Fr = cam::Frame;
  py::class_<Fr>(m, "Frame")
      .PS_RO(Fr, frame_id)
      .PS_RO(Fr, width_px)
      .PS_RO(Fr, height_px)
      .PS_RO(Fr, format)
      .def_property_readonly("counts", [](const Fr& f) { return counts_to_numpy(f); })
      .PS_RO(Fr, exposure_s)
      .PS_RO(Fr, trigger_time_s)
      .PS_RO(Fr, device_timestamp_ns)
      .PS_RO(Fr, system_timestamp_ns);
  using Pp = cam::PlatePose;
  py::class_<Pp>(m, "PlatePose")
      .def(py::init<>())
      .PS_RW(Pp, time_s)
      .PS_RW(Pp, piston_nm)
      .PS_RW(Pp, theta_x_urad)
      .PS_RW(Pp, theta_y_urad);
}

// (status, frame): the frame only when status is OK.
py::tuple status_and_frame(cam::FrameStatus status, cam::Frame&& frame) {
  if (status != cam::FrameStatus::kOk)
    return py::make_tuple(status, py::none());
  return py::make_tuple(status, std::move(frame));
}

void bind_camera_class(py::module_& m) {
  using Cm = cam::Camera;
  py::class_<Cm, std::unique_ptr<Cm>>(m, "Camera")
      .def("configure", &Cm::configure, py::arg("settings"),
           py::call_guard<py::gil_scoped_release>())
      .def("start", &Cm::start, py::call_guard<py::gil_scoped_release>())
      .def("trigger", &Cm::trigger, py::arg("loop_time_s"),
           "Starts one exposure at loop time loop_time_s; False (message says why) when refused")
      .def(
          "poll",
          [](Cm& c) {
            cam::Frame f;
            const cam::FrameStatus s = c.poll(f);
            return status_and_frame(s, std::move(f));
          },
          "(FrameStatus, Frame or None) without waiting: NONE when nothing has arrived")
      .def(
          "wait",
          [](Cm& c, double timeout_s) {
            cam::Frame f;
            cam::FrameStatus s;
            {
              py::gil_scoped_release release;
              s = c.wait(f, timeout_s);
            }
            return status_and_frame(s, std::move(f));
          },
          py::arg("timeout_s"), "(FrameStatus, Frame or None), waiting up to timeout_s")
      .def("stop", &Cm::stop, py::call_guard<py::gil_scoped_release>())
      .def("observe_plate", &Cm::observe_plate, py::arg("pose"),
           "The plate's true pose at one loop tick (the twin camera renders its exposure from "
           "these; other cameras ignore it)")
      .def_property_readonly("name", &Cm::name)
      .def_property_readonly("settings", &Cm::settings)
      .def_property_readonly("message", &Cm::message)
      .def_property_readonly("lost_frames", &Cm::lost_frames);
  m.def(
      "make_camera",
      [](const std::string& spec, const std::optional<cam::CameraConfig>& config,
         const cam::TwinScene* scene) {
        return cam::make_camera(spec, config.value_or(cam::CameraConfig{}), scene);
      },
      py::arg("spec"), py::arg("config") = py::none(), py::arg("scene") = py::none(),
      "A configured camera from its spec: 'twin' (renders scene), 'files:DIR', 'aravis:ID'; "
      "InputError naming the spec or the setting it cannot take");
  m.def("aravis_available", &cam::aravis_available, "True when this build links Aravis");
}

}  // namespace

void bind_camera(py::module_& m) {
  bind_camera_enums(m);
  bind_camera_config(m);
  bind_twin_scene(m);
  bind_frame(m);
  bind_camera_class(m);
}

}  // namespace piezoshift::python
