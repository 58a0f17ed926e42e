#include "piezoshift/psi/stage.hpp"

#include <algorithm>
#include <cmath>

#include "piezoshift/experiments/bench.hpp"

namespace piezoshift::psi {

BenchStage::BenchStage(experiments::Bench& bench, double base_um, double settle_s)
    : bench_(bench), base_um_(base_um) {
  bench_.drive_points({base_um_, base_um_, base_um_});
  bench_.run(settle_s);
  origin_ = {0.0, 0.0, 0.0, 0.0};
  origin_ = pose();
}

PoseSample BenchStage::pose() const {
  const plant::TwinTruth& t = bench_.twin().truth();
  return {t.time_s, 1000.0 * t.plate_z_um - origin_.piston_nm,
          t.theta_x_urad - origin_.theta_x_urad, t.theta_y_urad - origin_.theta_y_urad};
}

double BenchStage::time_s() const {
  return bench_.time_s();
}

void BenchStage::tick() {
  bench_.run(bench_.sample_time_s());
  const control::ControllerOutput& out = bench_.last_output();
  double err = 0.0;
  for (std::size_t i = 0; i < 3; ++i)
    err = std::max(err, 1000.0 * std::fabs(out.target_um[i] - out.feedback_um[i]));
  log_.push_back({bench_.time_s(), command_nm_, err, pose()});
}

void BenchStage::move(double piston_nm) {
  command_nm_ = piston_nm;
  const double z = base_um_ + piston_nm / 1000.0;
  bench_.drive_points({z, z, z});
}

bool BenchStage::wait_on_target(const OnTarget& c) {
  const double t0 = bench_.time_s(), dt = bench_.sample_time_s();
  double inside_since = -1.0;
  while (bench_.time_s() - t0 < c.timeout_s) {
    tick();
    const bool inside = log_.back().gauge_error_nm <= c.band_nm;
    if (!inside) {
      inside_since = -1.0;
      continue;
    }
    if (inside_since < 0.0)
      inside_since = bench_.time_s();
    if (bench_.time_s() - inside_since >= c.hold_s - 0.5 * dt)
      return true;
  }
  return false;
}

std::vector<PoseSample> BenchStage::expose(double exposure_s) {
  const double dt = bench_.sample_time_s();
  const auto ticks = std::max<long>(1, std::lround(exposure_s / dt));
  std::vector<PoseSample> poses{pose()};
  for (long k = 0; k < ticks; ++k) {
    tick();
    poses.push_back(log_.back().truth);
  }
  return poses;
}

}  // namespace piezoshift::psi
