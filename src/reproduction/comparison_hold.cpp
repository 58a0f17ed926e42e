#include "piezoshift/reproduction/comparison_hold.hpp"

#include <chrono>
#include <stdexcept>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/core/wall_time.hpp"
#include "piezoshift/instrument/twin_hold.hpp"

namespace piezoshift::reproduction {

const char* hold_key(HoldVariant v) {
  switch (v) {
    case HoldVariant::kPaperUnlocked:
      return "paper_unlocked";
    case HoldVariant::kPaperLocked:
      return "paper_locked";
    case HoldVariant::kImprovedUnlocked:
      return "improved_unlocked";
    case HoldVariant::kImprovedLocked:
      return "improved_locked";
  }
  return "";
}

bool hold_of_improved(HoldVariant v) {
  return v == HoldVariant::kImprovedUnlocked || v == HoldVariant::kImprovedLocked;
}

bool hold_locked(HoldVariant v) {
  return v == HoldVariant::kPaperLocked || v == HoldVariant::kImprovedLocked;
}

camera::InstrumentConfig hold_instrument_config(const config::ProjectConfig& config) {
  camera::InstrumentConfig ic;
  ic.installation.project = config;
  ic.installation.project.twin.cavity.in_fringes = true;
  // 96 px: the lock's fit is a frame's cost, and a minute is thousands of frames (docs/fizeau.md
  // measured the hold on this camera).
  ic.camera.settings.width_px = ic.camera.settings.height_px = 96;
  return ic;
}

HoldRun run_hold(const config::ProjectConfig& config,
                 const control::SemiClosedLoopParams& controller, const rig::Validity& calibrated,
                 std::uint64_t seed, bool lock, double hold_s) {
  HoldRun run;
  if (!calibrated.valid) {
    run.validity = calibrated;
    return run;
  }
  const auto start = std::chrono::steady_clock::now();
  calibration::LoopCalibration cal;
  cal.params = controller;
  cal.source = "compare's calibration";
  instrument::TwinHoldOptions o;
  o.seed = seed;
  o.averages = kHoldAverages;
  o.hold_s = hold_s;
  o.lock = lock;
  o.rate_Hz = 1.0 / config.twin.daq.sample_time_s;  // the rate the controller was calibrated at
  try {
    const instrument::TwinHold h = instrument::twin_hold(hold_instrument_config(config), cal, o);
    run.validity = h.sequence.validity;
    run.frames = h.summary.frames;
    run.simulated_time_s = static_cast<double>(h.sequence.ticks) / o.rate_Hz;
    if (run.validity.valid && !h.summary.path_error_rms_nm)
      run.validity.fail("the hold has no truth");
    if (run.validity.valid && !h.summary.path_error_1s_means_rms_nm)
      run.validity.fail("the hold has no whole second");
    if (run.validity.valid) {
      run.path_error_rms_nm = *h.summary.path_error_rms_nm;
      run.path_error_1s_means_rms_nm = *h.summary.path_error_1s_means_rms_nm;
    }
  } catch (const core::InputError& e) {
    run.validity.fail(fmt::format("the hold: {}", e.what()));
  } catch (const std::invalid_argument& e) {  // e.g. a camera the twin cannot render
    run.validity.fail(fmt::format("the hold: {}", e.what()));
  }
  run.wall_time_s = core::seconds_since(start);
  return run;
}

}  // namespace piezoshift::reproduction
