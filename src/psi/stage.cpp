#include "piezoshift/psi/stage.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "piezoshift/rig/bench.hpp"

namespace piezoshift::psi {

BenchStage::BenchStage(rig::Bench& bench, double base_um, double settle_s)
    : bench_(bench), base_um_(base_um) {
  bench_.drive_points({base_um_, base_um_, base_um_});
  bench_.run(settle_s);
  origin_ = {0.0, 0.0, 0.0, 0.0};
  origin_ = pose();
}

PoseSample BenchStage::pose() const {
  const plant::TwinTruth& t = bench_.twin().truth();
  // the piston the fringes see: the plate's, and the cavity's drift when it is switched on
  return {t.time_s, bench_.twin().fringe_piston_nm() - origin_.piston_nm,
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
  // Each channel's error |S - feedback| averaged over the last hold_s: single samples carry the
  // gauges' white and flicker noise (docs/twin.md, ~1.5 nm rms each), which a band of a few nm
  // on raw samples would mistake for motion.
  const double t0 = bench_.time_s(), dt = bench_.sample_time_s();
  const auto n = static_cast<std::size_t>(std::max(1L, std::lround(c.hold_s / dt)));
  std::vector<std::array<double, 3>> window;
  window.reserve(n);
  std::size_t next = 0;
  while (bench_.time_s() - t0 < c.timeout_s) {
    tick();
    const control::ControllerOutput& out = bench_.last_output();
    std::array<double, 3> e{};
    for (std::size_t i = 0; i < 3; ++i)
      e[i] = 1000.0 * (out.target_um[i] - out.feedback_um[i]);
    if (window.size() < n)
      window.push_back(e);
    else
      window[next] = e;
    next = (next + 1) % n;
    if (window.size() < n)
      continue;
    bool inside = true;
    for (std::size_t i = 0; i < 3; ++i) {
      double sum = 0.0;
      for (const auto& w : window)
        sum += w[i];
      inside = inside && std::fabs(sum / static_cast<double>(n)) <= c.band_nm;
    }
    if (inside)
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
