#include "piezoshift/calibration/polynomial_identification.hpp"

#include <stdexcept>

namespace piezoshift::calibration {

using control::Vec3;

PolynomialIdentificationResult identify_polynomial(rig::Bench& bench,
                                                   const PolynomialIdentificationOptions& o,
                                                   const rig::Progress& progress) {
  if (o.points < kPolyFitMinPoints || !(o.max_um > 0.0) || !(o.settle_s >= 0.0)) {
    throw std::invalid_argument("polynomial identification: at least 5 points and max > 0");
  }
  control::SemiClosedLoopParams params = bench.controller_params();
  params.polynomial = control::CubicPolynomial::identity();
  bench.set_controller(params);
  PolynomialIdentificationResult r;
  for (std::size_t k = 0; k < o.points; ++k) {
    const double c = o.max_um * static_cast<double>(k) / static_cast<double>(o.points - 1);
    bench.drive_points(Vec3{c, c, c});
    bench.run(o.settle_s);
    const rig::StaticMeasurement m = bench.measure_static();
    if (bench.last_output().saturated_mask != 0) {
      ++r.saturated_points;
    } else {
      r.command_um.push_back(c);
      r.measured_um.push_back((m.points_um[0] + m.points_um[1] + m.points_um[2]) / 3.0);
    }
    if (progress)
      progress(static_cast<double>(k + 1), static_cast<double>(o.points), "polynomial p");
  }
  r.simulated_time_s = bench.time_s();
  r.fit = fit_cubic_polynomial(r.measured_um, r.command_um);
  return r;
}

}  // namespace piezoshift::calibration
