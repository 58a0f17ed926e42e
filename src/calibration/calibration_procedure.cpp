#include "piezoshift/calibration/calibration_procedure.hpp"

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"

namespace piezoshift::calibration {

CalibrationOptions CalibrationOptions::paper_gains_only() {
  CalibrationOptions o;
  o.pid = PidChoice::kPaper;
  const control::PidGains paper{};
  o.pid_tuning.kp_values = {paper.kp};
  o.pid_tuning.ki_values = {paper.ki};
  o.pid_tuning.kd_values = {paper.kd};
  return o;
}

CalibrationWithTravel calibrate_with_travel(const config::ProjectConfig& config, std::uint64_t seed,
                                            const CalibrationOptions& options,
                                            const rig::Progress& progress) {
  CalibrationWithTravel out;
  control::SemiClosedLoopParams base;
  base.sample_time_s = config.twin.daq.sample_time_s;  // the controller runs at the DAQ's rate
  out.calibration = calibrate(config, base, seed, options, progress);
  experiments::TravelRangeOptions travel = options.travel;
  travel.bench.limits = options.limits;
  out.travel = experiments::run_travel_range(config, out.calibration.controller, seed + 3, travel);
  if (!(out.travel.single_move_um > 0.0))
    throw rig::ProcedureFailed(
        fmt::format("calibration: the calibrated loop has no semi-closed-loop travel: {}",
                    out.travel.validity.reason));
  return out;
}

CalibrationOutcome calibrate(const config::ProjectConfig& config,
                             const control::SemiClosedLoopParams& base, std::uint64_t seed,
                             const CalibrationOptions& options, const rig::Progress& progress) {
  CalibrationOutcome out;
  // Stage 1: the inner loops, unless gains were chosen on the identified plant.
  out.controller = base;
  out.controller.gains_sample_time_s = base.sample_time_s;
  if (options.holding_gains) {
    out.controller.gains = *options.holding_gains;
  } else {
    PidTuningOptions pid_tuning = options.pid_tuning;
    pid_tuning.limits = options.limits;
    out.pid = tune_pid(config, base, seed, pid_tuning, progress);
    out.controller.gains =
        options.pid == PidChoice::kPaper ? out.pid.paper.gains : out.pid.best.gains;
  }
  // Stage 2: A, identity feedforward not involved (inner loops only).
  out.controller.polynomial = control::CubicPolynomial::identity();
  out.controller.matrix = control::TransmissionMatrix::identity();
  // A stage whose supervisor tripped measured nothing: the calibration cannot go on.
  const auto check = [](const rig::Bench& bench, const char* stage) {
    if (bench.faulted()) {
      const runtime::FaultRecord& f = bench.fault();
      throw rig::ProcedureFailed(
          fmt::format("calibration {}: the safety supervisor tripped ({}, channel {}, at {:.3f} s)",
                      stage, runtime::to_string(f.reason), f.channel + 1,
                      static_cast<double>(f.tick) * bench.sample_time_s()));
    }
  };
  {
    rig::Bench bench(config, out.controller, seed + 1, {rig::Feedback::kGauges, options.limits});
    out.matrix = identify_matrix(bench, options.matrix, progress);
    check(bench, "stage 2 (matrix A)");
  }
  out.controller.matrix = out.matrix.fit.a;
  // Stage 3: p, with the gains and A in place.
  {
    rig::Bench bench(config, out.controller, seed + 2, {rig::Feedback::kGauges, options.limits});
    out.polynomial = identify_polynomial(bench, options.polynomial, progress);
    check(bench, "stage 3 (polynomial p)");
  }
  out.controller.polynomial = out.polynomial.fit.p;
  return out;
}

}  // namespace piezoshift::calibration
