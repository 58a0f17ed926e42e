#include "piezoshift/calibration/calibration_procedure.hpp"

namespace piezoshift::calibration {

CalibrationOutcome calibrate(const io::ProjectConfig& config,
                             const control::SemiClosedLoopParams& base, std::uint64_t seed,
                             const CalibrationOptions& options,
                             const experiments::Progress& progress) {
  CalibrationOutcome out;
  // Stage 1: the inner loops.
  out.pid = tune_pid(config, base, seed, options.pid_tuning, progress);
  out.controller = base;
  out.controller.gains_sample_time_s = base.sample_time_s;
  out.controller.gains =
      options.pid == PidChoice::kPaper ? out.pid.paper.gains : out.pid.best.gains;
  // Stage 2: A, identity feedforward not involved (inner loops only).
  out.controller.polynomial = control::CubicPolynomial::identity();
  out.controller.matrix = control::TransmissionMatrix::identity();
  {
    experiments::Bench bench(config, out.controller, seed + 1);
    out.matrix = identify_matrix(bench, options.matrix, progress);
  }
  out.controller.matrix = out.matrix.fit.a;
  // Stage 3: p, with the gains and A in place.
  {
    experiments::Bench bench(config, out.controller, seed + 2);
    out.polynomial = identify_polynomial(bench, options.polynomial, progress);
  }
  out.controller.polynomial = out.polynomial.fit.p;
  return out;
}

}  // namespace piezoshift::calibration
