#include "piezoshift/runtime/sim_backend.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"

namespace piezoshift::runtime {

plant::TwinParams twin_params_at_period(plant::TwinParams p, std::int64_t period_ns) {
  p.daq.sample_time_s = static_cast<double>(period_ns) * 1e-9;
  const double control_rate_Hz = 1.0 / p.daq.sample_time_s;
  const double substeps = std::ceil(p.physics_rate_Hz / control_rate_Hz - 1e-9);
  p.physics_rate_Hz = control_rate_Hz * (substeps < 1.0 ? 1.0 : substeps);
  return p;
}

SimBackend::SimBackend(SimOptions options) : options_(std::move(options)) {}
SimBackend::~SimBackend() = default;

void SimBackend::configure() {
  if (!(options_.rate_Hz > 0.0) || !std::isfinite(options_.rate_Hz))
    throw core::InputError(fmt::format("sim: rate {} Hz is not > 0", options_.rate_Hz));
  period_ns_ = std::llround(1e9 / options_.rate_Hz);
  const plant::TwinParams p = twin_params_at_period(options_.twin, period_ns_);
  // The config was valid at its own DAQ period; at the loop's rate it may not be (the physics
  // rate rounded up past its range, or no longer a multiple of the interferometer's).
  const auto cannot = [&](const std::string& why) {
    return core::InputError(fmt::format("sim at {} Hz: the twin of {} cannot be built: {}",
                                        options_.rate_Hz, options_.source, why));
  };
  if (const std::string problem = plant::twin_params_problem(options_.design, p); !problem.empty())
    throw cannot(problem);
  try {
    twin_ = std::make_unique<plant::Twin>(options_.design, p, options_.seed);
  } catch (const std::invalid_argument& e) {
    throw cannot(e.what());
  }
}

void SimBackend::activate() {
  if (!twin_)
    throw core::InputError("sim: activate() before configure()");
  staged_ = Vec3{};
  twin_->write_ao(staged_);
  line_staged_ = line_high_ = false;
  for (TriggerEdge stale{}; wire_.try_pop(stale);) {  // a previous run's, never taken
  }
  active_ = true;
}

void SimBackend::deactivate() noexcept {
  if (!twin_)
    return;
  staged_ = Vec3{};
  twin_->write_ao(staged_);
  line_staged_ = line_high_ = false;
  active_ = false;
}

DaqStatus SimBackend::read(const CycleTime& t, Vec3& ai_V) noexcept {
  if (!active_)
    return DaqStatus::kInactive;
  std::int64_t n = (t.period_ns + period_ns_ / 2) / period_ns_;
  if (n < 1)
    n = 1;
  // A tick that took longer than its period must not make the next one longer still: the twin
  // falls behind the clock instead (the supervisor's overrun rule trips on such a loop anyway).
  if (n > kMaxCatchUpPeriods)
    n = kMaxCatchUpPeriods;
  for (std::int64_t i = 0; i < n; ++i)
    twin_->advance();
  ai_V = twin_->read_ai();
  last_ai_ = ai_V;
  twin_->write_ao(staged_);
  if (line_staged_ != line_high_) {
    line_high_ = line_staged_;
    if (line_high_) {
      ++edges_;
      if (!wire_.try_push(TriggerEdge{t.tick, t.since_start_ns}))
        ++edges_dropped_;
    }
  }
  return DaqStatus::kOk;
}

DaqStatus SimBackend::write(const CycleTime&, const Vec3& ao_V) noexcept {
  if (!active_)
    return DaqStatus::kInactive;
  staged_ = ao_V;
  for (double v : ao_V)
    if (!(v >= -10.0 && v <= 10.0))
      return DaqStatus::kClamped;  // the twin's converter saturates (or keeps a NaN channel)
  return DaqStatus::kOk;
}

bool SimBackend::truth(Vec3& z_um, Vec3& interferometer_um) const noexcept {
  if (!twin_)
    return false;
  z_um = twin_->truth().points_um;
  interferometer_um = twin_->interferometer().dynamic_um;
  return true;
}

double SimBackend::fringe_drift_nm() const noexcept {
  return twin_ ? twin_->fringe_piston_nm() - 1000.0 * twin_->truth().plate_z_um : 0.0;
}

bool SimBackend::inject(FaultKind kind, std::size_t channel,
                        const FaultInjectionParams& params) noexcept {
  if (!twin_ || channel >= 3)
    return false;
  plant::ChannelFault f = twin_->fault(channel);
  switch (kind) {
    case FaultKind::kSgsOpen:
      f.sgs_open = true;
      break;
    case FaultKind::kSgsStuck:
      f.sgs_stuck = true;
      break;
    case FaultKind::kAdcNan:
      f.adc_nan = true;
      break;
    case FaultKind::kAdcSpike:
      // towards the far end of the range, as the emulation does; the ADC clips it
      f.adc_spike_V = last_ai_[channel] < 5.0 ? params.spike_V : -params.spike_V;
      break;
    case FaultKind::kAmplifierFail:
      f.amplifier_failed = true;
      break;
    case FaultKind::kActuatorCrack:
      f.stack_stiffness_scale = params.crack_stiffness_factor;
      break;
    case FaultKind::kOverrunBurst:
      return false;
  }
  try {
    twin_->set_fault(channel, f);
  } catch (...) {
    return false;
  }
  return true;
}

}  // namespace piezoshift::runtime
