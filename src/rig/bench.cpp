#include "piezoshift/rig/bench.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/plant/simulation_cost.hpp"
#include "piezoshift/rig/simulation_meter.hpp"

namespace piezoshift::rig {

const char* to_string(Feedback feedback) noexcept {
  return feedback == Feedback::kOracle ? "oracle" : "gauges";
}

Bench::Bench(const config::ProjectConfig& config, const control::SemiClosedLoopParams& controller,
             std::uint64_t seed, const BenchOptions& options)
    : options_(options),
      sample_time_s_(config.twin.daq.sample_time_s),
      steps_per_tick_(static_cast<std::uint64_t>(
          plant::estimate_simulation_cost(config.twin, sample_time_s_).physics_steps + 0.5)) {
  if (std::fabs(controller.sample_time_s - sample_time_s_) > 1e-12 * sample_time_s_) {
    throw std::invalid_argument(
        "bench: the controller's sample time differs from the DAQ's period");
  }
  runtime::SimOptions so;
  so.design = config.design;
  so.twin = config.twin;
  so.seed = seed;
  so.rate_Hz = 1.0 / sample_time_s_;
  sim_ = std::make_unique<runtime::SimBackend>(so);
  try {
    sim_->configure();
  } catch (const core::InputError& e) {
    throw std::invalid_argument(e.what());
  }
  daq_ = sim_.get();
  if (options.feedback == Feedback::kOracle) {
    oracle_ = std::make_unique<runtime::OracleBackend>(*sim_, controller.matrix, controller.scaling,
                                                       options.oracle_notch, sample_time_s_);
    daq_ = oracle_.get();
  }
  // Owner mode: the procedures drive it between ticks; it runs until the bench is destroyed and
  // keeps running after a fault (its ramp to 0 V, then latched), as a bench left switched on.
  runtime::LoopConfig lc;
  lc.rate_Hz = so.rate_Hz;
  lc.duration_s = std::numeric_limits<double>::infinity();
  lc.stop_when_safe_after_fault = false;
  lc.owner_drives = true;
  loop_ = std::make_unique<runtime::ControlLoop>(lc, controller, options.limits, *daq_, clock_,
                                                 runtime::SetpointProfile::step(0.0));
  daq_->activate();
  loop_->start();
}

Bench::~Bench() {
  daq_->deactivate();
}

void Bench::set_controller(const control::SemiClosedLoopParams& params) {
  const control::ParamsProblem problem = loop_->try_configure(params);
  if (problem != control::ParamsProblem::kNone)
    throw std::invalid_argument(runtime::refused_controller_message("bench", problem));
}

void Bench::drive_open_loop(const Vec3& ao_V) {
  loop_->drive_open_loop(ao_V);
}

void Bench::drive_actuators(const Vec3& target_um) {
  loop_->drive_actuators(target_um);
}

void Bench::drive_points(const Vec3& zd_um) {
  loop_->drive_points(zd_um);
}

namespace {
// The process's totals (simulation_meter.hpp); ns of simulated time, to sum exactly.
std::atomic<std::uint64_t> g_ticks{0}, g_simulated_ns{0}, g_static{0}, g_physics_steps{0};
}  // namespace

SimulationMeter simulation_meter() noexcept {
  SimulationMeter m;
  m.ticks = g_ticks.load(std::memory_order_relaxed);
  m.simulated_s = static_cast<double>(g_simulated_ns.load(std::memory_order_relaxed)) * 1e-9;
  m.static_measurements = g_static.load(std::memory_order_relaxed);
  m.physics_steps = g_physics_steps.load(std::memory_order_relaxed);
  return m;
}

void Bench::tick() {
  // The bench never asks the loop to stop, so the loop never ends a run on its own.
  loop_->tick();
  g_ticks.fetch_add(1, std::memory_order_relaxed);
  g_simulated_ns.fetch_add(static_cast<std::uint64_t>(loop_->period_ns()),
                           std::memory_order_relaxed);
  g_physics_steps.fetch_add(steps_per_tick_, std::memory_order_relaxed);
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
  g_static.fetch_add(1, std::memory_order_relaxed);
  // The window in progress began before this call; the one after it is wholly ours.
  const plant::InterferometerReading& ifm = sim_->twin().interferometer();
  const std::uint64_t start = ifm.static_count;
  while (ifm.static_count < start + 1)
    tick();
  Vec3 sgs_sum{};
  std::size_t n = 0;
  while (ifm.static_count < start + 2) {
    tick();
    const Vec3& fb = last_output().feedback_um;
    for (std::size_t i = 0; i < 3; ++i)
      sgs_sum[i] += fb[i];
    ++n;
  }
  StaticMeasurement m;
  m.points_um = ifm.static_um;
  m.window_end_s = ifm.static_time_s;
  for (std::size_t i = 0; i < 3; ++i)
    m.sgs_um[i] = sgs_sum[i] / static_cast<double>(n);
  return m;
}

}  // namespace piezoshift::rig
