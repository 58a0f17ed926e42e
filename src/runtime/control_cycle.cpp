#include "piezoshift/runtime/control_cycle.hpp"

#include <stdexcept>
#include <string>

namespace piezoshift::runtime {

const char* to_string(DriveMode mode) noexcept {
  switch (mode) {
    case DriveMode::kOpenLoop:
      return "open-loop";
    case DriveMode::kActuators:
      return "actuators";
    case DriveMode::kPoints:
      return "points";
  }
  return "unknown";
}

std::string refused_controller_message(std::string_view source, control::ParamsProblem problem) {
  return std::string(source) + ": the loop refused the controller: " + control::to_string(problem);
}

ControlCycle::ControlCycle(const control::SemiClosedLoopParams& params,
                           const SafetyLimits& limits) {
  const control::ParamsProblem problem = control::params_problem(params, params.sample_time_s);
  if (problem != control::ParamsProblem::kNone)
    throw std::invalid_argument(std::string("control cycle: ") + control::to_string(problem) +
                                " (sample time " + std::to_string(params.sample_time_s) + " s)");
  controller_.configure(params);
  supervisor_.configure(limits, params.sample_time_s, params.scaling);
}

control::ParamsProblem ControlCycle::try_configure(
    const control::SemiClosedLoopParams& params) noexcept {
  const control::ParamsProblem problem =
      control::params_problem(params, controller_.params().sample_time_s);
  if (problem != control::ParamsProblem::kNone)
    return problem;
  // The scaling is the wiring the supervisor was set up with.
  if (params.scaling != controller_.params().scaling)
    return control::ParamsProblem::kScaling;
  const Vec3 held = held_command_um();
  controller_.configure(params);
  controller_.reset_to(held);
  return problem;
}

Vec3 ControlCycle::held_command_um() const noexcept {
  const Vec3& ao = supervisor_.last_output_V();
  Vec3 u{};
  for (std::size_t i = 0; i < u.size(); ++i) {
    const control::SignalScaling& s = controller_.params().scaling[i];
    u[i] = s.dac_to_um(ao[i]);
  }
  return u;
}

void ControlCycle::restart_from_outputs() noexcept {
  controller_.reset_to(held_command_um());
  controller_.hold_integrators(false);
}

void ControlCycle::enter(DriveMode mode) noexcept {
  if (mode_ == DriveMode::kOpenLoop && mode != DriveMode::kOpenLoop)
    restart_from_outputs();
  mode_ = mode;
  zd_um_ = actuator_target_um_ = open_loop_V_ = Vec3{};
}

void ControlCycle::drive_open_loop(const Vec3& ao_V) noexcept {
  enter(DriveMode::kOpenLoop);
  open_loop_V_ = ao_V;
}

void ControlCycle::drive_actuators(const Vec3& target_um) noexcept {
  enter(DriveMode::kActuators);
  actuator_target_um_ = target_um;
}

void ControlCycle::drive_points(const Vec3& zd_um) noexcept {
  enter(DriveMode::kPoints);
  zd_um_ = zd_um;
}

bool ControlCycle::clear_fault() noexcept {
  if (!supervisor_.clear_fault())
    return false;
  controller_.reset();
  controller_.hold_integrators(false);
  return true;
}

void ControlCycle::reset() noexcept {
  supervisor_.reset();
  controller_.configure(controller_.params());
  mode_ = DriveMode::kOpenLoop;
  zd_um_ = actuator_target_um_ = open_loop_V_ = Vec3{};
  previous_write_ = DaqStatus::kOk;
  last_ = CycleSample{};
}

const CycleSample& ControlCycle::step(DaqBackend& daq, const CycleTime& t,
                                      bool previous_tick_overran) noexcept {
  CycleSample& c = last_;
  c.tick = t.tick;
  c.mode = mode_;
  c.zd_um = zd_um_;
  c.actuator_target_um = actuator_target_um_;
  c.open_loop_V = open_loop_V_;
  c.read_status = daq.read(t, c.ai_V);
  switch (mode_) {
    case DriveMode::kPoints:
      c.controller = controller_.update(zd_um_, c.ai_V);
      break;
    case DriveMode::kActuators:
      c.controller = controller_.update_actuators(actuator_target_um_, c.ai_V);
      break;
    case DriveMode::kOpenLoop:
      c.controller = control::ControllerOutput{};
      c.controller.dac_V = open_loop_V_;
      for (std::size_t i = 0; i < c.ai_V.size(); ++i)
        c.controller.feedback_um[i] = controller_.params().scaling[i].sgs_to_um(c.ai_V[i]);
      c.controller.target_um = c.controller.feedback_um;
      break;
  }
  SupervisorInput in{};
  in.closed_loop = mode_ != DriveMode::kOpenLoop;
  in.tick = t.tick;
  in.period_s = static_cast<double>(t.period_ns) * 1e-9;
  in.sgs_V = c.ai_V;
  in.request_V = c.controller.dac_V;
  in.target_um = c.controller.target_um;
  in.feedback_um = c.controller.feedback_um;
  in.read_status = c.read_status;
  in.previous_write_status = previous_write_;
  in.previous_tick_overran = previous_tick_overran;
  c.supervisor = supervisor_.update(in);
  controller_.hold_integrators(c.supervisor.hold_integrators);
  c.write_status = daq.write(t, c.supervisor.ao_V);
  previous_write_ = c.write_status;
  return c;
}

}  // namespace piezoshift::runtime
