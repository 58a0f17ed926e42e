#pragma once
// The paper's three-stage calibration (Section 3), inner loop to outer loop, on the twin:
//   1. PID gains        pid_tuning.hpp (or the paper's gains, PidChoice::kPaper, still scored)
//   2. matrix A         matrix_identification.hpp, with the stage-1 gains
//   3. polynomial p     polynomial_identification.hpp, with the stage-1 gains and stage-2 A
// Each stage runs on its own fresh bench (seed, seed + 1, seed + 2: the same unit, new
// sessions). The result is the controller to load (SemiClosedLoopParams) and every stage's data.
#include <cstdint>

#include "piezoshift/calibration/matrix_identification.hpp"
#include "piezoshift/calibration/pid_tuning.hpp"
#include "piezoshift/calibration/polynomial_identification.hpp"
#include "piezoshift/experiments/progress.hpp"

namespace piezoshift::calibration {

enum class PidChoice : std::uint8_t {
  kPaper,   //!< keep the paper's kp, ki, kd (Section 4)
  kSearch,  //!< the grid search's winner
};

struct CalibrationOptions {
  PidChoice pid = PidChoice::kSearch;
  PidTuningOptions pid_tuning{};
  MatrixIdentificationOptions matrix{};
  PolynomialIdentificationOptions polynomial{};
};

struct CalibrationOutcome {
  control::SemiClosedLoopParams controller;  //!< gains, A and p found
  PidTuningResult pid;
  MatrixIdentificationResult matrix;
  PolynomialIdentificationResult polynomial;
};

//! base supplies the sample time, limits and scaling; its gains, A and p are replaced.
CalibrationOutcome calibrate(const io::ProjectConfig& config,
                             const control::SemiClosedLoopParams& base, std::uint64_t seed,
                             const CalibrationOptions& options = {},
                             const experiments::Progress& progress = {});

}  // namespace piezoshift::calibration
