#include "piezoshift/instrument/twin_hold.hpp"

#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "piezoshift/camera/make_camera.hpp"
#include "piezoshift/camera/twin_camera.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/instrument/acquisition.hpp"
#include "piezoshift/instrument/measurement_lock.hpp"
#include "piezoshift/instrument/twin_measurement.hpp"
#include "piezoshift/runtime/safety_ranges.hpp"

namespace piezoshift::instrument {
namespace {

SequenceParams hold_sequence(const TwinHoldOptions& o) {
  SequenceParams p;
  p.steps_rad = commanded_steps(psi::Algorithm::kHariharan5, {}, "--steps-rad");
  p.averages = o.averages;
  p.hold_s = o.hold_s;
  if (const std::string why = sequence_problem(p); !why.empty())
    throw core::InputError("twin hold: " + why);
  return p;
}

}  // namespace

TwinHold twin_hold(const camera::InstrumentConfig& config,
                   const calibration::LoopCalibration& calibration, const TwinHoldOptions& o) {
  SequenceParams params = hold_sequence(o);
  const camera::TwinScene scene =
      measurement_scene(psi::SurfaceSpec{}, config.camera, params, o.seed);
  const config::ProjectConfig& project = config.installation.project;
  if (const std::optional<std::string> who = lock_requested_by(o.lock, "--lock", calibration))
    params.lock =
        measurement_lock_setup(scene.mask, config.camera.pupil_radius_m, project.twin.geometry,
                               calibration, LockSetup{}.retake_s, params, *who);
  if (const std::string why =
          travel_problem(params, calibration.travel_z_max_um, calibration.source);
      !why.empty())
    throw core::InputError("twin hold: " + why);
  LoopSetup loop;
  loop.controller = calibration.params;
  loop.limits = runtime::resolve_overrun_trip(config.installation.safety, true);
  loop.rate_Hz = o.rate_Hz;
  std::unique_ptr<camera::Camera> cam = camera::make_camera("twin", config.camera, &scene);
  cam->start();
  TwinHold out;
  out.sequence = acquire_on_simulated_twin(project, o.seed, o.rate_Hz, "", *cam, loop, params);
  cam->stop();
  out.summary = hold_summary(out.sequence);
  return out;
}

}  // namespace piezoshift::instrument
