#pragma once
// `piezoshift reproduce`, the project's main job: the paper's method end to end on the twin.
//   calibration (3 stages)  seeds seed .. seed + 2           calibration_procedure.hpp
//   travel range            seeds seed + 10, seed + 11       paper_experiments.hpp
//   step response           seed + 20
//   linearity               seed + 30
//   repeatability 5 um      seed + 40
//   repeatability 10 um     seed + 50
//   linearity, 0.25 um grid seed + 60   (levels the calibration never saw)
//   linearity, downwards    seed + 70
//   linearity without the cubic  seed + 30 (the paper's protocol, p = identity: what p corrects)
//   phase step (lambda/8)   seed + 80   (beyond the paper: experiments/phase_step.hpp)
//   inner loop identified   seed + 90 at the DAQ's rate, seed + 91 at 10 kHz, with the margins
//                           of the calibrated PID on it (calibration/loop_identification.hpp)
//   a measurement           seed + 100  (Hariharan's 5 frames on the twin camera, through
//                           `measure`'s library path: phase_measurement.hpp)
// all with the calibrated controller (the paper's structure: PID, A, p), through the loop `run`
// and `serve` ship (rig/bench.hpp), supervisor included. Then the same experiments, same
// seeds, with the oracle (runtime/oracle_backend.hpp): the same loop fed the plate's true point
// displacements, with the calibrated A and an identity polynomial. Impossible on hardware, it is
// the floor no controller fed by the strain gauges can beat. Deterministic: the same
// configuration, seed and schedule give the same numbers bit for bit.
//
// valid() is false when any Table 4 experiment of the paper's controller is not valid
// (rig/validity.hpp) or the measurement is not (a sequence that failed, a fit that did not
// converge); `reproduce` then exits with kExitInvalidExperiment.
//
// Schedules: the full one is the paper's (230 moves per target, 10 s per linearity level, the
// full PID grid); the quick one keeps every step but shortens the calibration, the travel search
// and the linearity levels (tests, a first look). It keeps the 230 repeatability moves.
#include <cstdint>
#include <string>
#include <vector>

#include "piezoshift/calibration/calibration_procedure.hpp"
#include "piezoshift/calibration/loop_identification.hpp"
#include "piezoshift/config/project_config.hpp"
#include "piezoshift/experiments/paper_experiments.hpp"
#include "piezoshift/experiments/phase_step.hpp"
#include "piezoshift/reproduction/phase_measurement.hpp"
#include "piezoshift/runtime/stability_margins.hpp"

namespace piezoshift::reproduction {

struct ReproduceOptions {
  std::uint64_t seed = 1;
  bool quick = false;
  calibration::PidChoice pid = calibration::PidChoice::kPaper;
  //! The supervisor's limits on every bench, the calibration's, the experiments' and the
  //! measurement's (the installation's [safety]): a trip fails the calibration or the experiment.
  runtime::SafetyLimits limits{};
};

struct Schedule {
  calibration::CalibrationOptions calibration;
  experiments::TravelRangeOptions travel;
  experiments::StepExperimentOptions step;
  experiments::LinearityOptions linearity;
  experiments::RepeatabilityOptions repeat_5um;
  experiments::RepeatabilityOptions repeat_10um;
  experiments::LinearityOptions linearity_grid;  //!< the unseen 0.25 um grid
  experiments::LinearityOptions linearity_down;  //!< the paper's levels, downwards
  experiments::PhaseStepOptions phase_step;      //!< lambda/8 at mid-travel

  static Schedule paper();  //!< the full schedule (Section 4)
  static Schedule quick();  //!< shortened steps, same procedure
};

//! Exit status of `reproduce` when a Table 4 experiment is not valid.
inline constexpr int kExitInvalidExperiment = rig::kExitNotValid;

//! Table 4's experiments and the two extra linearity sweeps, for one controller.
struct ExperimentSet {
  experiments::TravelRangeResult travel;
  experiments::StepExperimentResult step;
  experiments::LinearityResult linearity;       //!< the paper's protocol (Section 4.2)
  experiments::LinearityResult linearity_grid;  //!< 0.25 um grid, upwards
  experiments::LinearityResult linearity_down;  //!< the paper's levels, downwards
  experiments::RepeatabilityResult repeat_5um;
  experiments::RepeatabilityResult repeat_10um;
  experiments::PhaseStepResult phase_step;  //!< beyond the paper: lambda/8, 1 ms exposures

  double experiments_simulated_time_s() const;
  //! Every Table 4 row (travel, step, linearity by the paper's protocol, repeatability) valid.
  bool table4_valid() const;
  //! "name: reason" for every experiment that is not valid (the extra ones included).
  std::vector<std::string> invalid_reasons() const;
};

//! The inner loop's identified plant at one sample time and the calibrated PID's margins on it.
struct InnerLoopAnalysis {
  double sample_time_s = 0.0;
  //! The calibrated PID's, per-sample gains at sample_time_s; for the improved controller its
  //! correction's integral gain (the margins are then the worse of the hold's gain and the
  //! boost's ceiling, calibration::correction_margins).
  control::PidParams pid;
  calibration::LoopIdentification plant;
  std::array<runtime::StabilityMargins, 3> margins{};
  //! Not valid when the twin cannot run at this rate (its physics rate is not a whole multiple)
  //! or the identification tripped the supervisor; plant and margins are then empty.
  rig::Validity validity;

  //! The worst of the three channels: the smallest gain margin, the smallest phase margin and
  //! its gain crossover.
  runtime::StabilityMargins worst() const;
};

//! The schedule with every experiment's feedback set to f (the oracle: Feedback::kOracle).
Schedule with_feedback(Schedule s, rig::Feedback f);
//! s with limits on every bench it sets up, the calibration's included.
Schedule with_limits(Schedule s, const runtime::SafetyLimits& limits);

//! Every experiment of the set with one controller, each on its own seed (the table above:
//! seed + 10 ... seed + 80). reproduce() and compare() run their controllers through this.
ExperimentSet run_experiment_set(const config::ProjectConfig& config,
                                 const control::SemiClosedLoopParams& controller,
                                 std::uint64_t seed, const Schedule& schedule,
                                 const rig::Progress& progress = {});

//! The second loop rate of reproduce and compare: 10 kHz, beside the DAQ's.
inline constexpr double kFastSampleTime_s = 1e-4;

//! The loop rates the inner loop is analysed at: the DAQ's, and 10 kHz unless that is the DAQ's.
std::vector<double> inner_loop_sample_times_s(const config::ProjectConfig& config);

//! The controller's inner loop identified at each rate of inner_loop_sample_times_s (seeds
//! seed + 90, seed + 91), with its PID's margins on it; the controller's gains re-expressed per
//! sample at each rate. A rate the twin cannot run at is an analysis that is not valid; so is the
//! 10 kHz one, not run, when not_at_10kHz gives the reason (compare: gains that ring up there).
std::vector<InnerLoopAnalysis> analyze_inner_loop(const config::ProjectConfig& config,
                                                  const control::SemiClosedLoopParams& controller,
                                                  std::uint64_t seed,
                                                  const std::string& not_at_10kHz = {});
//! One rate of analyze_inner_loop: the twin's DAQ and the controller's sample time set to
//! sample_time_s, identified on seed.
InnerLoopAnalysis analyze_inner_loop_at(const config::ProjectConfig& config,
                                        const control::SemiClosedLoopParams& controller,
                                        double sample_time_s, std::uint64_t seed);

//! The paper's controller's set (the base, so result.travel, result.step, ... are it) and the
//! oracle's.
struct ReproductionResult : ExperimentSet {
  ReproduceOptions options;
  Schedule schedule;  //!< what was run
  calibration::CalibrationOutcome calibration;
  control::SemiClosedLoopParams oracle_controller;  //!< gains and A calibrated, p = identity
  ExperimentSet oracle;
  //! The paper's protocol with the calibrated gains and A but p = identity, on the same seed as
  //! `linearity`: the semi-closed loop's own nonlinearity (SGS conditioner, ball contact), which
  //! the cubic is there to remove. Not a Table 4 row, so it does not count in valid().
  experiments::LinearityResult linearity_without_cubic;
  //! The calibrated PID's loop at the DAQ's rate (the paper's 1 kHz) and at 10 kHz (the same
  //! gains re-expressed per sample, the twin's DAQ at 0.1 ms) unless that is the DAQ's rate.
  std::vector<InnerLoopAnalysis> inner_loop;
  //! A phase-shifting measurement with the calibrated controller (seed + 100).
  PhaseMeasurement measurement;
  double simulated_time_s = 0.0;  //!< twin time over every stage and experiment
  double wall_time_s = 0.0;

  bool valid() const { return table4_valid() && measurement.validity.valid; }
  //! ExperimentSet's reasons, then the measurement's ("measurement: ...").
  std::vector<std::string> invalid_reasons() const;
};

ReproductionResult reproduce(const config::ProjectConfig& config, const ReproduceOptions& options,
                             const rig::Progress& progress = {});

}  // namespace piezoshift::reproduction
