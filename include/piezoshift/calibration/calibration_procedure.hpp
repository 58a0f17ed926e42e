#pragma once
// The paper's three-stage calibration (Section 3), inner loop to outer loop, on the twin:
//   1. PID gains        pid_tuning.hpp (or the paper's gains, PidChoice::kPaper, still scored)
//   2. matrix A         matrix_identification.hpp, with the stage-1 gains
//   3. polynomial p     polynomial_identification.hpp, with the stage-1 gains and stage-2 A
// Each stage runs on its own fresh bench (seed, seed + 1, seed + 2: the same unit, new
// sessions). The result is the controller to load (SemiClosedLoopParams) and every stage's data.
#include <cstdint>
#include <optional>

#include "piezoshift/calibration/matrix_identification.hpp"
#include "piezoshift/calibration/pid_tuning.hpp"
#include "piezoshift/calibration/polynomial_identification.hpp"
#include "piezoshift/experiments/paper_experiments.hpp"
#include "piezoshift/rig/progress.hpp"

namespace piezoshift::calibration {

enum class PidChoice : std::uint8_t {
  kPaper,   //!< keep the paper's kp, ki, kd (Section 4)
  kSearch,  //!< the grid search's winner
};

struct CalibrationOptions {
  PidChoice pid = PidChoice::kPaper;  //!< the paper's gains unless the search is asked for
  PidTuningOptions pid_tuning{};
  MatrixIdentificationOptions matrix{};
  PolynomialIdentificationOptions polynomial{};
  //! The semi-closed-loop travel measured after the three stages (calibrate_with_travel).
  experiments::TravelRangeOptions travel{};
  //! The supervisor's limits on every stage's bench and the travel's (the installation's
  //! [safety], as `run` uses them); they replace pid_tuning.limits and travel.bench.limits.
  runtime::SafetyLimits limits{};
  //! Gains (per sample at the base's rate) chosen on the identified plant before stage 1 would
  //! excite it (holding_gains.hpp): stage 1 is then not run and stages 2 and 3 hold with these.
  std::optional<control::PidGains> holding_gains;

  //! The paper's gains, scored alone (no grid): the quickest calibration, for `run` and `serve`
  //! on the twin without a calibration file.
  static CalibrationOptions paper_gains_only();
};

struct CalibrationOutcome {
  control::SemiClosedLoopParams controller;  //!< gains, A and p found
  PidTuningResult pid;
  MatrixIdentificationResult matrix;
  PolynomialIdentificationResult polynomial;
};

struct CalibrationWithTravel {
  CalibrationOutcome calibration;
  //! Section 4.1's semi-closed-loop travel with the calibrated controller, on a fourth session
  //! (seed + 3): what the calibration file's [travel] z_max_um and `serve`'s TMX? Z advertise.
  experiments::TravelRangeResult travel;
};

//! base supplies the sample time, limits and scaling; its gains, A and p are replaced.
CalibrationOutcome calibrate(const config::ProjectConfig& config,
                             const control::SemiClosedLoopParams& base, std::uint64_t seed,
                             const CalibrationOptions& options = {},
                             const rig::Progress& progress = {});

//! calibrate() at the twin's DAQ rate, then the travel. Throws core::InputError when the calibrated
//! loop cannot track even the travel search's first level (no travel to advertise).
CalibrationWithTravel calibrate_with_travel(const config::ProjectConfig& config, std::uint64_t seed,
                                            const CalibrationOptions& options = {},
                                            const rig::Progress& progress = {});

}  // namespace piezoshift::calibration
