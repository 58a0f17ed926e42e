#include "piezoshift/procedures/loop_station.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <fmt/core.h>

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/procedures/loop_setup.hpp"
#include "piezoshift/procedures/stage_model_setup.hpp"

namespace piezoshift::procedures {

using control::Vec3;

namespace {

void check(bool ok, const std::string& message) {
  if (!ok)
    throw core::InputError(message);
}

// serve's ranges for the same settings (check_serve_options).
void check_station_options(const LoopStationOptions& o, bool twin) {
  check_loop_rate(o.rate_Hz);
  check(o.on_target_um > 0.0 && std::isfinite(o.on_target_um),
        fmt::format("on_target_um {}: must be > 0", o.on_target_um));
  check(o.on_target_urad > 0.0 && std::isfinite(o.on_target_urad),
        fmt::format("on_target_urad {}: must be > 0", o.on_target_urad));
  check(o.settle_s >= 0.0 && o.settle_s <= 10.0,
        fmt::format("settle_s {}: must be 0 to 10 s", o.settle_s));
  check(twin || !o.free_run,
        fmt::format("free_run: paces the twin (daq sim-rt); {} keeps real time", o.daq));
}

// Ticks a wait lets pass between two looks at its condition: 5 ms of loop time.
constexpr double kWaitChunkS = 0.005;

std::string pose_text(const host::AxisValues& p) {
  return fmt::format("Z {:.4f} um, tip {:.3f} urad, tilt {:.3f} urad", p[0], p[1], p[2]);
}

}  // namespace

std::string StationFault::description() const {
  return fmt::format("{}{} at t = {:.4f} s (tick {})", name,
                     channel >= 1 ? fmt::format(" on channel {}", channel) : std::string(), t_s,
                     tick);
}

StationFaulted::StationFaulted(StationFault fault)
    : std::runtime_error("the safety supervisor latched a fault: " + fault.description() +
                         " (servo on clears it)"),
      fault_(std::move(fault)) {}

LoopStation::LoopStation(const LoopStationOptions& o)
    : rate_Hz_(o.rate_Hz), on_target_um_(o.on_target_um), on_target_urad_(o.on_target_urad) {
  const bool twin = o.daq == "sim" || o.daq == "sim-rt";
  check_station_options(o, twin);
  settle_ticks_ = static_cast<std::uint64_t>(std::max(1.0, std::round(o.settle_s * o.rate_Hz)));
  runtime::InstallationConfig installation;
  if (!o.config_path.empty())
    installation = runtime::load_installation_config(o.config_path);
  const runtime::SafetyLimits limits = loop_safety_limits(installation.safety, o.max_overruns);
  LoopStackOptions so;
  so.daq = twin ? "sim" : o.daq;
  so.rate_Hz = o.rate_Hz;
  so.seed = o.seed;
  so.config_path = o.config_path;
  so.clock = o.free_run ? StackClock::kPaced : StackClock::kRealTime;
  so.faults = o.faults;
  // The stack first: a bad fault, daq or device is named before the twin's calibration runs.
  stack_ = std::make_unique<LoopStack>(so, installation.project);
  safety_ = runtime::resolve_overrun_trip(limits, stack_->sim() != nullptr);
  calibration::LoopCalibration cal;
  if (o.calibration_path.empty() && o.calibration) {
    cal = *o.calibration;
    calibration::check_at_loop_rate(cal.params, 1.0 / o.rate_Hz, cal.source);
  } else {
    cal = resolve_calibration(o.calibration_path, so.daq, installation.project, o.seed,
                              1.0 / o.rate_Hz, o.max_physics_steps);
  }
  calibration::refuse_fringe_lock(cal, "the loop station");
  calibration_source_ = cal.source;
  model_ = std::make_unique<host::StageModel>(
      loop_stage_model(installation.project, cal, safety_, cal.source,
                       o.config_path.empty() ? "the built-in configuration" : o.config_path));
  rig::LoopRigOptions lo;
  lo.rate_Hz = o.rate_Hz;
  lo.request_realtime = o.request_realtime;
  rig_ = std::make_unique<rig::LoopRig>(stack_->daq(), stack_->clock(), stack_->paced(), cal.params,
                                        safety_, lo);
  rig_->set_observer([this](const runtime::HostSample& h) { take(h); });
  target_ = model_->pose_from_sgs(Vec3{});
}

LoopStation::~LoopStation() {
  try {
    close();
  } catch (...) {  // LoopRig's destructor stops the loop all the same
  }
}

void LoopStation::take(const runtime::HostSample& h) {
  have_sample_ = true;
  last_ = h;
  const bool faulted = h.state == static_cast<std::uint8_t>(runtime::SupervisorState::kFaulted);
  if (!clearing_)
    latch_fault(h);
  const host::AxisValues position = model_->pose_from_sgs(h.sgs_V);
  bool on = servo_on_ && !faulted && !moving_ && h.closed_loop != 0;
  for (std::size_t a = 0; a < 3 && on; ++a)
    on = std::fabs(position[a] - target_[a]) <= (a == 0 ? on_target_um_ : on_target_urad_);
  settled_ = on ? settled_ + 1 : 0;
  if (!recorder_.active() || recorder_.complete())
    return;
  host::RecorderInput in{};
  in.target = target_;
  in.position = position;
  in.interferometer = interferometer();
  in.channel_V = model_->channel_V_from_daq(h.ao_V);
  for (std::size_t i = 0; i < 3; ++i)
    in.sensor_um[i] = model_->params().controller.scaling[i].sgs_to_um(h.sgs_V[i]);
  recorder_.take(h.tick, h.t_s, in);
}

void LoopStation::latch_fault(const runtime::HostSample& h) {
  if (fault_ || h.state != static_cast<std::uint8_t>(runtime::SupervisorState::kFaulted))
    return;
  StationFault f;
  f.name = runtime::to_string(static_cast<runtime::FaultReason>(h.fault_reason));
  f.channel = h.fault_channel >= 0 ? h.fault_channel + 1 : -1;
  f.tick = h.tick;
  f.t_s = h.t_s;
  fault_ = std::move(f);
  servo_on_ = false;  // the supervisor holds the outputs at 0 V
}

void LoopStation::open_loop() {
  clearing_ = true;
  rig_->hold();
  clearing_ = false;
  fault_.reset();
  servo_on_ = false;
  latch_fault(last_);  // from the tick that applied it on, a latch is a new fault
}

void LoopStation::check_open() const {
  if (closed_)
    throw std::logic_error("the stage is closed");
}

void LoopStation::throw_if_faulted() const {
  if (fault_)
    throw StationFaulted(*fault_);
}

std::uint64_t LoopStation::ticks_of(double duration_s) const {
  const double ticks = duration_s * rate_Hz_;
  return ticks > 0.0 ? static_cast<std::uint64_t>(std::llround(std::min(ticks, 1e15))) : 0;
}

void LoopStation::run_ticks(std::uint64_t ticks) {
  const bool had = have_sample_;
  const std::uint64_t before = last_.tick;
  rig_->settle(static_cast<double>(ticks) / rate_Hz_);  // at least one tick more, unless it ended
  // The loop ends only when close() stops it; a wait that saw no tick would spin for ever.
  if (had && last_.tick == before)
    throw std::runtime_error("the control loop stopped: " + rig_->fault());
}

void LoopStation::update() {
  check_open();
  run_ticks(0);
}

void LoopStation::servo(bool on) {
  check_open();
  update();
  if (on && servo_on_)
    return;
  open_loop();  // the loop then closes from open loop, bumplessly
  if (!on)
    return;
  throw_if_faulted();  // one that latched again at once (a gauge still open)
  target_ = model_->pose_from_sgs(last_.sgs_V);
  moving_ = true;
  rig_->drive_points(model_->points_for(target_));
  moving_ = false;
  servo_on_ = true;
  settled_ = 0;
  latch_fault(last_);
  throw_if_faulted();
}

void LoopStation::move(const host::AxisValues& pose) {
  check_open();
  update();
  throw_if_faulted();
  if (!servo_on_)
    throw std::logic_error("move: the servo is off (servo on first)");
  for (std::size_t a = 0; a < 3; ++a)
    check(std::isfinite(pose[a]),
          fmt::format("move: {} {}: not a number", host::axis_name(host::kAxes[a]), pose[a]));
  if (const std::string why = model_->unreachable_reason(pose); !why.empty())
    throw core::InputError(fmt::format("move to {}: out of reach: {}", pose_text(pose), why));
  moving_ = true;
  target_ = pose;
  rig_->drive_points(model_->points_for(pose));
  moving_ = false;
  settled_ = 0;
}

bool LoopStation::on_target() const noexcept {
  return servo_on_ && !fault_ && settled_ >= settle_ticks_;
}

void LoopStation::wait_on_target(double timeout_s) {
  check_open();
  check(timeout_s >= 0.0 && timeout_s <= 1e6,
        fmt::format("wait_on_target: timeout_s {}: must be 0 to 1e6 s", timeout_s));
  update();
  throw_if_faulted();
  if (!servo_on_)
    throw std::logic_error("wait_on_target: the servo is off (servo on first)");
  const std::uint64_t from = last_.tick;
  const std::uint64_t limit = ticks_of(timeout_s);
  const std::uint64_t chunk = std::max<std::uint64_t>(1, ticks_of(kWaitChunkS));
  while (!on_target()) {
    throw_if_faulted();
    if (last_.tick - from >= limit)
      throw StationTimeout(fmt::format(
          "not on target after {:g} s: position {}, target {}, band {:g} um and {:g} urad held "
          "{:g} s",
          timeout_s, pose_text(position()), pose_text(target_), on_target_um_, on_target_urad_,
          static_cast<double>(settle_ticks_) / rate_Hz_));
    run_ticks(std::min(chunk, limit - (last_.tick - from)));
  }
}

host::AxisValues LoopStation::position() const {
  return model_->pose_from_sgs(last_.sgs_V);
}

host::AxisValues LoopStation::interferometer() const {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  return last_.has_truth != 0 ? model_->pose_from_points(last_.interferometer_um)
                              : host::AxisValues{nan, nan, nan};
}

Vec3 LoopStation::output_V() const {
  return last_.ao_V;
}

double LoopStation::time_s() const {
  return last_.t_s;
}

void LoopStation::record(std::size_t points, std::uint64_t every,
                         std::vector<RecorderSignal> signals) {
  check_open();
  update();
  recorder_.start(points, every, std::move(signals), last_.tick + 1);
}

const Recording& LoopStation::read_recording(double timeout_s) {
  check_open();
  check(timeout_s >= 0.0 && timeout_s <= 1e6,
        fmt::format("read_recording: timeout_s {}: must be 0 to 1e6 s", timeout_s));
  if (!recorder_.active())
    throw std::logic_error("read_recording: nothing recorded (record first)");
  const std::uint64_t from = last_.tick;
  const std::uint64_t limit = ticks_of(timeout_s);
  while (!recorder_.complete()) {
    if (last_.tick - from >= limit)
      throw StationTimeout(fmt::format("read_recording: {} of {} points after {:g} s",
                                       recorder_.recording().time_s.size(), recorder_.wanted(),
                                       timeout_s));
    // To the last point due, or a tick at a time once the link dropped one.
    const std::uint64_t due =
        recorder_.last_tick() > last_.tick ? recorder_.last_tick() - last_.tick : 1;
    run_ticks(std::min(due, limit - (last_.tick - from)));
  }
  return recorder_.recording();
}

void LoopStation::close() {
  if (closed_)
    return;
  closed_ = true;
  servo_on_ = false;
  rig_->stop();  // the loop's ramp to 0 V; its last samples pass through take()
}

}  // namespace piezoshift::procedures
