#include "piezoshift/rig/guided_rig.hpp"

#include <fmt/core.h>

namespace piezoshift::rig {

void BenchRig::set_controller(const control::SemiClosedLoopParams& params) {
  bench_.set_controller(params);
}

void BenchRig::rest(double settle_s) {
  if (bench_.ticks() == 0)
    return;
  bench_.drive_open_loop(Vec3{});
  bench_.run(settle_s);
}

RigWindow BenchRig::measure() {
  const rig::StaticMeasurement m = bench_.measure_static();
  RigWindow w;
  w.sgs_um = m.sgs_um;
  const double offset = continues_ != nullptr ? continues_->clock_s() : 0.0;
  w.end_s = offset + m.window_end_s;
  w.start_s = w.end_s - window_s_;
  w.saturated = bench_.last_output().saturated_mask != 0;
  w.twin_points_um = m.points_um;
  return w;
}

std::string BenchRig::fault() const {
  if (!bench_.faulted())
    return {};
  const runtime::FaultRecord& f = bench_.fault();
  return fmt::format("the safety supervisor tripped ({}, channel {}, at {:.3f} s)",
                     runtime::to_string(f.reason), f.channel + 1,
                     static_cast<double>(f.tick) * bench_.sample_time_s());
}

}  // namespace piezoshift::rig
