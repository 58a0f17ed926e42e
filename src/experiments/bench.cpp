#include "piezoshift/experiments/bench.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace piezoshift::experiments {

Bench::Bench(const io::ProjectConfig& config, const control::SemiClosedLoopParams& controller,
             std::uint64_t seed)
    : twin_(config.design, config.twin, seed),
      controller_(controller),
      sample_time_s_(config.twin.daq.sample_time_s) {
  if (std::fabs(controller.sample_time_s - sample_time_s_) > 1e-12 * sample_time_s_) {
    throw std::invalid_argument(
        "bench: the controller's sample time differs from the DAQ's period");
  }
}

Vec3 Bench::present_command_um() const {
  // The command that produced the AO volts now held, in the controller's um.
  const auto& ao = twin_.truth().ao_V;
  Vec3 u{};
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& s = controller_.params().scaling[i];
    u[i] = (ao[i] - s.drive_offset_V) / s.drive_V_per_um;
  }
  return u;
}

void Bench::set_controller(const control::SemiClosedLoopParams& params) {
  if (std::fabs(params.sample_time_s - sample_time_s_) > 1e-12 * sample_time_s_) {
    throw std::invalid_argument(
        "bench: the controller's sample time differs from the DAQ's period");
  }
  controller_.configure(params);
  controller_.reset_to(present_command_um());
}

void Bench::drive_open_loop(const Vec3& ao_V) {
  mode_ = DriveMode::kOpenLoop;
  setpoint_ = ao_V;
}

void Bench::drive_actuators(const Vec3& target_um) {
  if (mode_ == DriveMode::kOpenLoop)
    controller_.reset_to(present_command_um());
  mode_ = DriveMode::kActuators;
  setpoint_ = target_um;
}

void Bench::drive_points(const Vec3& zd_um) {
  if (mode_ == DriveMode::kOpenLoop)
    controller_.reset_to(present_command_um());
  mode_ = DriveMode::kPoints;
  setpoint_ = zd_um;
}

void Bench::tick() {
  const Vec3& sgs_V = twin_.read_ai();
  switch (mode_) {
    case DriveMode::kOpenLoop:
      out_ = control::ControllerOutput{};
      out_.dac_V = setpoint_;
      for (std::size_t i = 0; i < 3; ++i) {
        out_.feedback_um[i] = controller_.params().scaling[i].sgs_to_um(sgs_V[i]);
      }
      break;
    case DriveMode::kActuators:
      out_ = controller_.update_actuators(setpoint_, sgs_V);
      break;
    case DriveMode::kPoints:
      out_ = controller_.update(setpoint_, sgs_V);
      break;
  }
  twin_.step(out_.dac_V);
}

void Bench::run(double duration_s, const std::function<void(const Bench&)>& on_tick) {
  const auto n = static_cast<std::int64_t>(std::llround(duration_s / sample_time_s_));
  for (std::int64_t k = 0; k < std::max<std::int64_t>(n, 1); ++k) {
    tick();
    if (on_tick)
      on_tick(*this);
  }
}

StaticMeasurement Bench::measure_static() {
  // The window in progress began before this call; the one after it is wholly ours.
  const std::uint64_t start = twin_.interferometer().static_count;
  while (twin_.interferometer().static_count < start + 1)
    tick();
  Vec3 sgs_sum{};
  std::size_t n = 0;
  while (twin_.interferometer().static_count < start + 2) {
    tick();
    for (std::size_t i = 0; i < 3; ++i)
      sgs_sum[i] += out_.feedback_um[i];
    ++n;
  }
  StaticMeasurement m;
  m.points_um = twin_.interferometer().static_um;
  m.window_end_s = twin_.interferometer().static_time_s;
  for (std::size_t i = 0; i < 3; ++i)
    m.sgs_um[i] = sgs_sum[i] / static_cast<double>(n);
  return m;
}

}  // namespace piezoshift::experiments
