#pragma once
// A phase step, what the stage exists for (beyond the paper's Table 4). Held at start_um, the
// plate steps by lambda/8: 79.1 nm at 632.8 nm, a pi/2 phase step in a Fizeau cavity (the
// reflected beam's path changes by twice the displacement). A camera frame integrates the plate
// over its exposure, so the step is judged on the plate's true position (the twin's truth: mean
// of P1..P3 over every physics step) averaged over one exposure, 1 ms by default (the shortest
// exposure considered), not on the interferometer's 1 kHz samples:
//   hold jitter     rms of the exposure means over hold_s before the step, about their linear
//                   trend (drift is not jitter): the noise a phase step brings into a surface
//                   measurement, which a controller feeding the gauges' noise into the plate sets;
//   settling time   from the step command to the end of the last exposure whose mean lies outside
//                   +-tolerance_nm of the target (the level before the step + step_nm), within
//                   record_s; infinite when the record ends outside the band.
// The level before the step is the hold's trend line at the step instant. Seeds and the loop are
// the other experiments' (rig/bench.hpp): the shipping tick, supervisor included.
//   own settling    the same, for the stepped run minus a second run of the same seed without
//                   the step: a controller's own step with the wander the plant brings to a
//                   held plate (the gauges' drift, which a semi-closed loop follows) removed. It
//                   separates what a controller can improve from what the sensor limits.
//
// Not settling within +-1 nm is a result, not a failure. The experiment is not valid (validity)
// when the supervisor tripped, a PID sat at its output limit, or the plate ended further than
// target_tolerance_nm from the target (the step asked for was not the step made).
#include <cstdint>
#include <vector>

#include "piezoshift/config/project_config.hpp"
#include "piezoshift/control/semi_closed_loop.hpp"
#include "piezoshift/core/wavelength.hpp"
#include "piezoshift/rig/bench.hpp"
#include "piezoshift/rig/progress.hpp"
#include "piezoshift/rig/validity.hpp"

namespace piezoshift::experiments {

struct PhaseStepOptions {
  double wavelength_nm = core::kHeNeWavelength_nm;  //!< He-Ne, the Fizeau interferometer's source
  double start_um = 5.0;                            //!< mid-travel
  double settle_s = 1.0;             //!< at start_um before the hold (the approach's transient)
  double hold_s = 0.5;               //!< the hold whose jitter is measured
  double record_s = 0.1;             //!< after the step command
  double exposure_s = 1e-3;          //!< a camera exposure; a whole number of control periods
  double tolerance_nm = 1.0;         //!< the settling band
  double target_tolerance_nm = 5.0;  //!< beyond it the step did not reach its target
  rig::BenchOptions bench{};

  double step_nm() const { return wavelength_nm / 8.0; }
};

struct PhaseStepResult {
  std::vector<double> time_s;            //!< end of each exposure, from the step command
  std::vector<double> exposure_mean_nm;  //!< true plate over that exposure, from the level before
  double step_nm = 0.0;                  //!< asked for
  double hold_jitter_nm_rms = 0.0;
  double settling_time_s = 0.0;  //!< infinite when never within the band until the record's end
  double final_error_nm = 0.0;   //!< mean of the last 10 exposures minus step_nm
  //! The same run without the step (same seed: the same noise and drift), from its own level
  //! before: how far the plate wanders on its own over the record (what the gauges' drift and
  //! the controller's hold bring), and the settling time of the stepped run minus this one (the
  //! controller's own step, that wander removed).
  std::vector<double> still_exposure_mean_nm;
  double still_wander_nm = 0.0;  //!< largest |still_exposure_mean_nm|
  double own_settling_time_s = 0.0;
  rig::Validity validity;
  double simulated_time_s = 0.0;
};

//! The settling time of exposure means (times from the step command): the end of the last one
//! outside target +- tolerance, 0 when none is, infinite when the last one is. Throws
//! std::invalid_argument on empty or unequal series.
double exposure_settling_time_s(const std::vector<double>& time_s,
                                const std::vector<double>& value_nm, double target_nm,
                                double tolerance_nm);

PhaseStepResult run_phase_step(const config::ProjectConfig& config,
                               const control::SemiClosedLoopParams& controller, std::uint64_t seed,
                               const PhaseStepOptions& options, const rig::Progress& progress = {});

}  // namespace piezoshift::experiments
