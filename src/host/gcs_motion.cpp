// The GCS motion commands: servo, moves, stop, open-loop volts and the queries of where the stage
// is and should be.
#include "piezoshift/host/gcs_interpreter.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

#include "gcs_arguments.hpp"

namespace piezoshift::host {

using namespace gcs;

namespace {

using runtime::HostCommand;
constexpr std::size_t kGenerators = WaveGenerators::kGenerators;

}  // namespace

std::string GcsInterpreter::servo(Session& s, const Args& args) {
  std::vector<AxisValue> pairs;
  if (!accepted(s, parse_pairs(args, pairs)))
    return {};
  const double on = pairs.front().value;
  for (const AxisValue& p : pairs) {
    // One loop drives all three axes: the values must agree.
    if ((p.value != 0.0 && p.value != 1.0) || p.value != on) {
      fail(s, GcsError::kParamOutOfRange);
      return {};
    }
  }
  if ((on == 1.0) == servo_on_ && !faulted_) {
    trigger_.motion(sequence_);  // already so; still a motion command for the recorder's trigger
    return {};
  }
  HostCommand c{};
  if (on == 1.0) {
    if (!std::isfinite(position_[0]) || !std::isfinite(position_[1]) ||
        !std::isfinite(position_[2])) {
      fail(s, GcsError::kMotionError);
      return {};
    }
    c.kind = HostCommand::Kind::kServoOn;
    c.zd_um = model_.points_for(position_);
  } else {
    c.kind = HostCommand::Kind::kServoOff;
  }
  if (!send(s, c))
    return {};
  clear_sequence_ = sequence_;
  faulted_ = false;  // the loop clears the latch when it applies this command
  servo_on_ = on == 1.0;
  if (servo_on_) {
    target_ = position_;
    measured_target_ = {true, true, true};
  } else {
    hold_applied_volts();
  }
  moved();
  return {};
}

std::string GcsInterpreter::servo_query(Session& s, const Args& args) {
  std::string answer;
  const auto servo = [this](std::size_t) { return servo_on_ ? 1 : 0; };
  return reply(s, axis_lines(args, servo, answer), answer);
}

std::string GcsInterpreter::move(Session& s, const Args& args, bool relative) {
  std::vector<AxisValue> pairs;
  if (!accepted(s, parse_pairs(args, pairs)))
    return {};
  if (!servo_on_) {
    fail(s, GcsError::kServoOff);
    return {};
  }
  for (const AxisValue& p : pairs) {
    if (waves_.running(p.axis)) {
      fail(s, GcsError::kWaveGeneratorActive);
      return {};
    }
  }
  AxisValues target = target_;
  std::array<bool, 3> named{};
  for (const AxisValue& p : pairs) {
    target[p.axis] = relative ? target[p.axis] + p.value : p.value;
    named[p.axis] = true;
  }
  if (!model_.reachable(target) && !nominal_tilts(target, named)) {
    fail(s, GcsError::kPositionOutOfLimits);
    return {};
  }
  HostCommand c{};
  c.kind = HostCommand::Kind::kMoveTo;
  c.zd_um = model_.points_for(target);
  if (!send(s, c))
    return {};
  for (std::size_t a = 0; a < named.size(); ++a)
    measured_target_[a] = measured_target_[a] && !named[a] && target[a] == target_[a];
  target_ = target;
  moved();
  return {};
}

// A tilt target a MOV does not name but took from the gauges at servo-on or STP (their noise:
// about 0.1 urad) is set to its nominal 0 when it alone puts the move out of the travel, so that
// `MOV Z` to TMN? or TMX? alone is reached (docs/gcs.md, "Travel limits"). A tilt a client set
// is never changed.
bool GcsInterpreter::nominal_tilts(AxisValues& target, const std::array<bool, 3>& named) const {
  AxisValues nominal = target;
  bool changed = false;
  for (std::size_t a = 1; a < nominal.size(); ++a)
    if (!named[a] && measured_target_[a] && nominal[a] != 0.0) {
      nominal[a] = 0.0;
      changed = true;
    }
  if (!changed || !model_.reachable(nominal))
    return false;
  target = nominal;
  return true;
}

std::string GcsInterpreter::target_query(Session& s, const Args& args) {
  std::string answer;
  const AxisValues target = commanded();
  return reply(s, axis_lines(args, fixed(target, 6), answer), answer);
}

std::string GcsInterpreter::position_query(Session& s, const Args& args) {
  std::string answer;
  return reply(s, axis_lines(args, fixed(position_, 6), answer), answer);
}

std::string GcsInterpreter::on_target_query(Session& s, const Args& args) {
  std::string answer;
  const auto on = [this](std::size_t a) {
    return servo_on_ && settled_[a] >= settle_samples_ ? 1 : 0;
  };
  return reply(s, axis_lines(args, on, answer), answer);
}

// A PID at its limit while the axis is on target (at rest at the bottom of the travel) is no
// overflow: overflow_monitor.hpp.
std::string GcsInterpreter::overflow_query(Session& s, const Args& args) {
  std::string answer;
  const auto value = [this](std::size_t a) { return overflow_.overflow(a) ? 1 : 0; };
  return reply(s, axis_lines(args, value, answer), answer);
}

std::string GcsInterpreter::stop(Session& s, const Args&) {
  if (!stop_waves(s))
    return {};
  HostCommand c{};
  if (servo_on_) {
    c.kind = HostCommand::Kind::kMoveTo;
    c.zd_um = model_.points_for(position_);
  } else {
    c.kind = HostCommand::Kind::kOpenLoop;
    c.ao_V = last_.ao_V;
  }
  if (!send(s, c))
    return {};
  if (servo_on_) {
    target_ = position_;
    measured_target_ = {true, true, true};
  } else {
    hold_applied_volts();
  }
  moved();
  fail(s, GcsError::kStopped);
  return {};
}

std::string GcsInterpreter::moving_query(Session&, const Args&) {
  return fmt::format("{:X}\n", moving_mask());
}

std::string GcsInterpreter::velocity(Session& s, const Args& args) {
  std::vector<AxisValue> pairs;
  if (!accepted(s, parse_pairs(args, pairs)))
    return {};
  for (const AxisValue& p : pairs) {
    if (!(p.value > 0.0)) {
      fail(s, GcsError::kVelocityOutOfLimits);
      return {};
    }
  }
  for (const AxisValue& p : pairs)
    velocity_[p.axis] = p.value;
  return {};
}

std::string GcsInterpreter::velocity_query(Session& s, const Args& args) {
  std::string answer;
  return reply(s, axis_lines(args, fixed(velocity_, 6), answer), answer);
}

std::string GcsInterpreter::velocity_control_query(Session& s, const Args& args) {
  std::string answer;
  const auto off = [](std::size_t) { return 0; };
  return reply(s, axis_lines(args, off, answer), answer);
}

std::string GcsInterpreter::open_loop(Session& s, const Args& args) {
  std::vector<AxisValue> pairs;
  if (!accepted(s, parse_pairs(args, pairs)))
    return {};
  if (servo_on_) {
    fail(s, GcsError::kOpenLoopWithServoOn);
    return {};
  }
  if (faulted_) {
    fail(s, GcsError::kMotionError);  // latched: SVO clears it first
    return {};
  }
  AxisValues values = open_loop_V_;
  for (const AxisValue& p : pairs)
    values[p.axis] = p.value;
  const Vec3 channel_V = model_.channel_V_for(values);
  const auto& params = model_.params();
  HostCommand c{};
  c.kind = HostCommand::Kind::kOpenLoop;
  for (std::size_t i = 0; i < 3; ++i) {
    if (channel_V[i] < -1e-9 || channel_V[i] > params.channel_max_V + 1e-9) {
      fail(s, GcsError::kVoltageOutOfLimits);
      return {};
    }
    c.ao_V[i] = std::clamp(channel_V[i], 0.0, params.channel_max_V) / params.amplifier_gain;
  }
  if (!send(s, c))
    return {};
  open_loop_V_ = values;
  moved();
  return {};
}

std::string GcsInterpreter::open_loop_query(Session& s, const Args& args) {
  std::string answer;
  return reply(s, axis_lines(args, fixed(open_loop_V_, 4), answer), answer);
}

std::string GcsInterpreter::voltage_query(Session& s, const Args& args) {
  std::string answer;
  const Vec3 channel_V = model_.channel_V_from_daq(last_.ao_V);
  const auto volts = [&channel_V](int ch) {
    return fmt::format("{:.4f}", channel_V[static_cast<std::size_t>(ch - 1)]);
  };
  return reply(s, id_lines(args, 3, GcsError::kParamOutOfRange, volts, answer), answer);
}

std::string GcsInterpreter::lower_limit_query(Session& s, const Args& args) {
  std::string answer;
  const AxisValues limits = model_.min_limits();
  return reply(s, axis_lines(args, fixed(limits, 6), answer), answer);
}

std::string GcsInterpreter::upper_limit_query(Session& s, const Args& args) {
  std::string answer;
  const AxisValues limits = model_.max_limits();
  return reply(s, axis_lines(args, fixed(limits, 6), answer), answer);
}

void GcsInterpreter::moved() {
  move_sequence_ = sequence_;
  settled_ = {};
  trigger_.motion(sequence_);
}

AxisValues GcsInterpreter::commanded() const {
  AxisValues c = target_;
  if (!have_sample_)
    return c;
  const AxisValues live = model_.pose_from_points(last_.zd_um);
  for (std::size_t g = 0; g < kGenerators; ++g)
    if (waves_.playing(g, last_.applied_sequence))
      c[g] = live[g];
  return c;
}

unsigned GcsInterpreter::moving_mask() const {
  unsigned mask = 0;
  for (std::size_t a = 0; a < 3; ++a) {
    const bool moving =
        waves_.running(a) || (servo_on_ && !faulted_ && settled_[a] < settle_samples_);
    if (moving)
      mask |= 1u << a;
  }
  return mask;
}

void GcsInterpreter::hold_applied_volts() {
  open_loop_V_ = model_.open_loop_for(model_.channel_V_from_daq(last_.ao_V));
}

}  // namespace piezoshift::host
