#include "piezoshift/calibration/matrix_identification.hpp"

#include <stdexcept>

namespace piezoshift::calibration {

using control::Vec3;

MatrixIdentificationResult identify_matrix(rig::Bench& bench, const MatrixIdentificationOptions& o,
                                           const rig::Progress& progress) {
  if (!(o.repeats >= 1) || !(o.move_um > 0.0) || !(o.base_um >= 0.0) || !(o.settle_s >= 0.0)) {
    throw std::invalid_argument("matrix identification: repeats >= 1, move > 0, base >= 0");
  }
  MatrixIdentificationResult r;
  const Vec3 base{o.base_um, o.base_um, o.base_um};
  const double total = 3.0 * o.repeats;
  for (int rep = 0; rep < o.repeats; ++rep) {
    for (std::size_t i = 0; i < 3; ++i) {
      bench.drive_actuators(base);
      bench.run(o.settle_s);
      const rig::StaticMeasurement m0 = bench.measure_static();
      Vec3 moved = base;
      moved[i] += o.move_um;
      bench.drive_actuators(moved);
      bench.run(o.settle_s);
      const rig::StaticMeasurement m1 = bench.measure_static();
      Vec3 ds{}, dz{};
      for (std::size_t j = 0; j < 3; ++j) {
        ds[j] = m1.sgs_um[j] - m0.sgs_um[j];
        dz[j] = m1.points_um[j] - m0.points_um[j];
      }
      r.ds_um.push_back(ds);
      r.dz_um.push_back(dz);
      if (progress)
        progress(3.0 * rep + static_cast<double>(i) + 1.0, total, "matrix A");
    }
  }
  bench.drive_actuators(base);
  r.simulated_time_s = bench.time_s();
  r.fit = fit_transmission_matrix(r.ds_um, r.dz_um);
  return r;
}

}  // namespace piezoshift::calibration
