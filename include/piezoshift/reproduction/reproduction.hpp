#pragma once
// `piezoshift reproduce`, the project's main job: the paper's method end to end on the twin.
//   calibration (3 stages)  seeds seed .. seed + 2           calibration_procedure.hpp
//   travel range            seeds seed + 10, seed + 11       paper_experiments.hpp
//   step response           seed + 20
//   linearity               seed + 30
//   repeatability 5 um      seed + 40
//   repeatability 10 um     seed + 50
// all with the calibrated controller (the paper's structure: PID, A, p). Deterministic: the same
// configuration, seed and schedule give the same numbers bit for bit.
//
// Schedules: the full one is the paper's (230 moves per target, 10 s per linearity level, the
// full PID grid); the quick one keeps every step but shortens the calibration, the travel search
// and the linearity levels (tests, a first look). It keeps the 230 repeatability moves.
#include <cstdint>

#include "piezoshift/calibration/calibration_procedure.hpp"
#include "piezoshift/experiments/paper_experiments.hpp"
#include "piezoshift/io/project_config.hpp"

namespace piezoshift::reproduction {

struct ReproduceOptions {
  std::uint64_t seed = 1;
  bool quick = false;
  calibration::PidChoice pid = calibration::PidChoice::kPaper;
};

struct Schedule {
  calibration::CalibrationOptions calibration;
  experiments::TravelRangeOptions travel;
  experiments::StepExperimentOptions step;
  experiments::LinearityOptions linearity;
  experiments::RepeatabilityOptions repeat_5um;
  experiments::RepeatabilityOptions repeat_10um;

  static Schedule paper();  //!< the full schedule (Section 4)
  static Schedule quick();  //!< shortened steps, same procedure
};

struct ReproductionResult {
  ReproduceOptions options;
  Schedule schedule;  //!< what was run
  calibration::CalibrationOutcome calibration;
  experiments::TravelRangeResult travel;
  experiments::StepExperimentResult step;
  experiments::LinearityResult linearity;
  experiments::RepeatabilityResult repeat_5um;
  experiments::RepeatabilityResult repeat_10um;
  double simulated_time_s = 0.0;  //!< twin time over every stage and experiment
  double wall_time_s = 0.0;
};

ReproductionResult reproduce(const io::ProjectConfig& config, const ReproduceOptions& options,
                             const experiments::Progress& progress = {});

}  // namespace piezoshift::reproduction
