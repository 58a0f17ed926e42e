#include "piezoshift/host/gcs_controller.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <utility>

#include <fmt/core.h>

#include "piezoshift/runtime/safety_supervisor.hpp"

namespace piezoshift::host {

namespace {

using runtime::HostCommand;

// The commands HLP? lists, with their syntax; the table in docs/gcs.md says more.
constexpr std::array<std::string_view, 25> kHelp{
    "*IDN? - identification",
    "CSV? - GCS syntax version",
    "SAI? [ALL] - axis identifiers",
    "PUN? [{axis}] - position units",
    "HLP? - this list",
    "ERR? - oldest queued error number (0: none), removed from the queue",
    "SVO {axis} {0|1} ... - servo (semi-closed loop) off or on, all axes together",
    "SVO? [{axis} ...] - servo state",
    "MOV {axis} {position} ... - move to absolute position (servo on)",
    "MVR {axis} {distance} ... - move relative to the target (servo on)",
    "MOV? [{axis} ...] - target position",
    "POS? [{axis} ...] - position from the strain gauges",
    "ONT? [{axis} ...] - on target",
    "STP - stop: hold where the stage is (sets error 10)",
    "SVA {axis} {volts} ... - open-loop value in amplifier volts (servo off)",
    "SVA? [{axis} ...] - open-loop value",
    "VOL? [{channel} ...] - amplifier output voltage of channel 1, 2, 3",
    "TMN? [{axis} ...] - lower travel limit",
    "TMX? [{axis} ...] - upper travel limit",
    "DRC {table} {source} {option} - record option of source in table",
    "DRC? [{table} ...] - record configuration",
    "RTR {cycles} - record every n-th servo cycle",
    "RTR? - record rate in servo cycles",
    "DRL? [{table} ...] - points recorded",
    "DRR? [{start} [{count} [{table} ...]]] - read recorded data; TNR? - number of tables"};

// GCS framing: every line but the last ends with a space before the LF.
std::string framed(const std::vector<std::string>& lines) {
  std::string out;
  for (std::size_t i = 0; i < lines.size(); ++i)
    out += lines[i] + (i + 1 < lines.size() ? " \n" : "\n");
  return out;
}

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> tokens;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t'))
      ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t')
      ++i;
    if (i > start)
      tokens.push_back(line.substr(start, i - start));
  }
  return tokens;
}

bool parse_real(std::string_view s, double& value) {
  const char* end = s.data() + s.size();
  const auto r = std::from_chars(s.data(), end, value);
  return r.ec == std::errc{} && r.ptr == end && std::isfinite(value);
}

bool parse_integer(std::string_view s, long long& value) {
  const char* end = s.data() + s.size();
  const auto r = std::from_chars(s.data(), end, value);
  return r.ec == std::errc{} && r.ptr == end;
}

int axis_of(std::string_view s) {
  for (Axis a : kAxes)
    if (s == axis_name(a))
      return static_cast<int>(a);
  return -1;
}

struct AxisValue {
  std::size_t axis;
  double value;
};

// "{axis} {value} ..." pairs; kNone on success.
GcsError parse_pairs(const std::vector<std::string_view>& args, std::vector<AxisValue>& out) {
  if (args.empty() || args.size() % 2 != 0)
    return GcsError::kParamCount;
  std::array<bool, 3> seen{};
  for (std::size_t i = 0; i < args.size(); i += 2) {
    const int axis = axis_of(args[i]);
    if (axis < 0)
      return GcsError::kInvalidAxis;
    if (seen[static_cast<std::size_t>(axis)])
      return GcsError::kDoubleAxis;
    seen[static_cast<std::size_t>(axis)] = true;
    double v = 0.0;
    if (!parse_real(args[i + 1], v))
      return GcsError::kInvalidReal;
    out.push_back(AxisValue{static_cast<std::size_t>(axis), v});
  }
  return GcsError::kNone;
}

// "[{axis} ...]", all axes when empty; kNone on success.
GcsError parse_axes(const std::vector<std::string_view>& args, std::vector<std::size_t>& out) {
  if (args.empty()) {
    out = {0, 1, 2};
    return GcsError::kNone;
  }
  for (std::string_view a : args) {
    const int axis = axis_of(a);
    if (axis < 0)
      return GcsError::kInvalidAxis;
    out.push_back(static_cast<std::size_t>(axis));
  }
  return GcsError::kNone;
}

// "[{n} ...]" integers in [1, max], all when empty; kNone on success.
GcsError parse_ids(const std::vector<std::string_view>& args, int max, std::vector<int>& out,
                   GcsError out_of_range) {
  if (args.empty()) {
    for (int i = 1; i <= max; ++i)
      out.push_back(i);
    return GcsError::kNone;
  }
  for (std::string_view a : args) {
    long long v = 0;
    if (!parse_integer(a, v))
      return GcsError::kParamSyntax;
    if (v < 1 || v > max)
      return out_of_range;
    out.push_back(static_cast<int>(v));
  }
  return GcsError::kNone;
}

// One "key=value" line per requested axis (all when none), or the parse error.
template <typename Value>
GcsError axis_lines(const std::vector<std::string_view>& args, Value value, std::string& answer) {
  std::vector<std::size_t> axes;
  if (const GcsError e = parse_axes(args, axes); e != GcsError::kNone)
    return e;
  std::vector<std::string> lines;
  for (std::size_t a : axes)
    lines.push_back(fmt::format("{}={}", axis_name(kAxes[a]), value(a)));
  answer = framed(lines);
  return GcsError::kNone;
}

// One "n=value" line per requested channel or table in [1, max] (all when none).
template <typename Value>
GcsError id_lines(const std::vector<std::string_view>& args, int max, GcsError out_of_range,
                  Value value, std::string& answer) {
  std::vector<int> ids;
  if (const GcsError e = parse_ids(args, max, ids, out_of_range); e != GcsError::kNone)
    return e;
  std::vector<std::string> lines;
  for (int id : ids)
    lines.push_back(fmt::format("{}={}", id, value(id)));
  answer = framed(lines);
  return GcsError::kNone;
}

}  // namespace

GcsController::GcsController(const StageModel& model, runtime::HostLink& link, double servo_cycle_s,
                             const GcsOptions& options)
    : model_(model),
      link_(link),
      servo_cycle_s_(servo_cycle_s),
      options_(options),
      settle_samples_(static_cast<std::uint64_t>(
          std::max(1.0, std::round(options.settle_time_s / servo_cycle_s)))) {
  position_ = model_.pose_from_sgs(Vec3{});
}

void GcsController::on_connect(ClientId client) {
  sessions_[client] = Session{};
}

void GcsController::on_disconnect(ClientId client) {
  sessions_.erase(client);
}

void GcsController::fail(Session& session, GcsError error) {
  ++stats_.errors;
  if (session.errors.size() < options_.error_queue_length)
    session.errors.push_back(error);
}

std::string GcsController::on_overlong_line(ClientId client) {
  fail(sessions_[client], GcsError::kCommandTooLong);
  return {};
}

std::string GcsController::on_line(ClientId client, std::string_view line) {
  drain();
  ++stats_.lines;
  Session& session = sessions_[client];
  std::vector<std::string_view> tokens = split(line);
  if (tokens.empty())
    return {};
  const std::string_view name = tokens.front();
  tokens.erase(tokens.begin());
  return execute(session, name, tokens);
}

bool GcsController::send(Session& session, HostCommand command) {
  command.sequence = ++sequence_;
  if (!link_.commands.try_push(command)) {
    fail(session, GcsError::kCommunication);
    return false;
  }
  ++stats_.commands_sent;
  return true;
}

void GcsController::moved() {
  move_sequence_ = sequence_;
  settled_ = {};
  recorder_.restart();
}

void GcsController::drain() {
  runtime::HostSample s{};
  while (link_.samples.try_pop(s))
    take(s);
}

void GcsController::take(const runtime::HostSample& s) {
  if (have_sample_ && s.tick > last_.tick + 1)
    stats_.samples_missed += s.tick - last_.tick - 1;
  ++stats_.samples;
  last_ = s;
  have_sample_ = true;

  const bool faulted = s.state == static_cast<std::uint8_t>(runtime::SupervisorState::kFaulted);
  // Samples from before an SVO reached the loop show a latch that the SVO clears: not news. From
  // the SVO's tick on, a latch is a new fault, even one that recurs in that very tick.
  if (s.applied_sequence >= clear_sequence_) {
    if (faulted && !faulted_) {
      ++stats_.faults;
      servo_on_ = false;
      for (auto& [id, session] : sessions_)
        fail(session, GcsError::kMotionError);
    }
    faulted_ = faulted;
  }

  position_ = model_.pose_from_sgs(s.sgs_V);
  const bool counting =
      servo_on_ && !faulted && s.closed_loop != 0 && s.applied_sequence >= move_sequence_;
  for (std::size_t a = 0; a < 3; ++a) {
    const double tol = a == 0 ? options_.on_target_tolerance_um : options_.on_target_tolerance_urad;
    settled_[a] = counting && std::fabs(position_[a] - target_[a]) <= tol ? settled_[a] + 1 : 0;
  }

  RecorderInput in{};
  in.target = target_;
  in.position = position_;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  in.interferometer =
      s.has_truth != 0 ? model_.pose_from_points(s.interferometer_um) : AxisValues{nan, nan, nan};
  const auto& p = model_.params();
  in.channel_V = model_.channel_V_from_daq(s.ao_V);
  for (std::size_t i = 0; i < 3; ++i)
    in.sensor_um[i] = p.controller.scaling[i].sgs_to_um(s.sgs_V[i]);
  recorder_.record(in);
  if (observer_ != nullptr)
    observer_->on_sample(s, in);
}

bool GcsController::accepted(Session& s, GcsError error) {
  if (error == GcsError::kNone)
    return true;
  fail(s, error);
  return false;
}

std::string GcsController::reply(Session& s, GcsError error, std::string& answer) {
  return accepted(s, error) ? std::move(answer) : std::string{};
}

void GcsController::hold_applied_volts() {
  open_loop_V_ = model_.open_loop_for(model_.channel_V_from_daq(last_.ao_V));
}

std::string GcsController::execute(Session& s, std::string_view name, const Args& args) {
  std::string answer;
  const auto no_args = [&]() {
    if (!args.empty()) {
      fail(s, GcsError::kParamCount);
      return false;
    }
    return true;
  };
  if (name == "*IDN?")
    return no_args() ? options_.identification + "\n" : std::string{};
  if (name == "CSV?")
    return no_args() ? std::string{"2.0\n"} : std::string{};
  if (name == "ERR?") {
    if (!no_args())
      return {};
    int code = 0;
    if (!s.errors.empty()) {
      code = static_cast<int>(s.errors.front());
      s.errors.pop_front();
    }
    return fmt::format("{}\n", code);
  }
  if (name == "HLP?") {
    if (!no_args())
      return {};
    std::vector<std::string> lines{"The following commands are valid:"};
    for (std::string_view h : kHelp)
      lines.emplace_back(h);
    lines.emplace_back("Axes: Z piston (um), U tip theta_x (urad), V tilt theta_y (urad)");
    return framed(lines);
  }
  if (name == "SAI?") {
    if (args.size() > 1 || (args.size() == 1 && args[0] != "ALL")) {
      fail(s, GcsError::kParamSyntax);
      return {};
    }
    return framed({"Z", "U", "V"});
  }
  if (name == "PUN?")
    return reply(s,
                 axis_lines(
                     args, [](std::size_t a) { return axis_unit(kAxes[a]); }, answer),
                 answer);
  if (name == "MOV")
    return move(s, args, false);
  if (name == "MVR")
    return move(s, args, true);
  if (name == "SVO")
    return servo(s, args);
  if (name == "SVA")
    return open_loop(s, args);
  if (name == "STP")
    return stop(s, args);
  const auto fixed = [](const AxisValues& v, int digits) {
    return [&v, digits](std::size_t a) { return fmt::format("{:.{}f}", v[a], digits); };
  };
  if (name == "MOV?")
    return reply(s, axis_lines(args, fixed(target_, 6), answer), answer);
  if (name == "POS?")
    return reply(s, axis_lines(args, fixed(position_, 6), answer), answer);
  if (name == "SVA?")
    return reply(s, axis_lines(args, fixed(open_loop_V_, 4), answer), answer);
  if (name == "TMN?")
    return reply(s, axis_lines(args, fixed(model_.min_limits(), 6), answer), answer);
  if (name == "TMX?")
    return reply(s, axis_lines(args, fixed(model_.max_limits(), 6), answer), answer);
  if (name == "SVO?") {
    const auto servo = [this](std::size_t) { return servo_on_ ? 1 : 0; };
    return reply(s, axis_lines(args, servo, answer), answer);
  }
  if (name == "ONT?") {
    const auto on = [this](std::size_t a) { return servo_on_ && settled_[a] >= settle_samples_; };
    return reply(s,
                 axis_lines(
                     args, [&](std::size_t a) { return on(a) ? 1 : 0; }, answer),
                 answer);
  }
  if (name == "VOL?") {
    const Vec3 channel_V = model_.channel_V_from_daq(last_.ao_V);
    const auto volts = [&channel_V](int ch) {
      return fmt::format("{:.4f}", channel_V[static_cast<std::size_t>(ch - 1)]);
    };
    return reply(s, id_lines(args, 3, GcsError::kParamOutOfRange, volts, answer), answer);
  }
  if (name == "DRC")
    return recorder_config(s, args);
  if (name == "DRC?") {
    const auto table = [this](int t) { return recorder_.describe_table(t); };
    return reply(s, id_lines(args, DataRecorder::kTables, GcsError::kNoRecordTable, table, answer),
                 answer);
  }
  if (name == "RTR")
    return recorder_rate(s, args);
  if (name == "RTR?")
    return no_args() ? fmt::format("{}\n", recorder_.rate()) : std::string{};
  if (name == "TNR?")
    return no_args() ? fmt::format("{}\n", DataRecorder::kTables) : std::string{};
  if (name == "DRL?") {
    const auto points = [this](int t) {
      return recorder_.describe_table(t) != "0 0" ? recorder_.points() : 0;
    };
    return reply(s, id_lines(args, DataRecorder::kTables, GcsError::kNoRecordTable, points, answer),
                 answer);
  }
  if (name == "DRR?")
    return recorder_read(s, args);
  fail(s, GcsError::kUnknownCommand);
  return {};
}

std::string GcsController::move(Session& s, const Args& args, bool relative) {
  std::vector<AxisValue> pairs;
  if (!accepted(s, parse_pairs(args, pairs)))
    return {};
  if (!servo_on_) {
    fail(s, GcsError::kServoOff);
    return {};
  }
  AxisValues target = target_;
  for (const AxisValue& p : pairs)
    target[p.axis] = relative ? target[p.axis] + p.value : p.value;
  if (!model_.reachable(target)) {
    fail(s, GcsError::kPositionOutOfLimits);
    return {};
  }
  HostCommand c{};
  c.kind = HostCommand::Kind::kMoveTo;
  c.zd_um = model_.points_for(target);
  if (!send(s, c))
    return {};
  target_ = target;
  moved();
  return {};
}

std::string GcsController::servo(Session& s, const Args& args) {
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
    recorder_.restart();  // already so; still a motion command for the recorder's trigger
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
  } else {
    hold_applied_volts();
  }
  moved();
  return {};
}

std::string GcsController::open_loop(Session& s, const Args& args) {
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

std::string GcsController::stop(Session& s, const Args& args) {
  if (!args.empty()) {
    fail(s, GcsError::kParamCount);
    return {};
  }
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
  } else {
    hold_applied_volts();
  }
  moved();
  fail(s, GcsError::kStopped);
  return {};
}

std::string GcsController::recorder_config(Session& s, const Args& args) {
  if (args.size() != 3) {
    fail(s, GcsError::kParamCount);
    return {};
  }
  long long table = 0;
  long long option = 0;
  if (!parse_integer(args[0], table) || !parse_integer(args[2], option)) {
    fail(s, GcsError::kParamSyntax);
    return {};
  }
  if (table < 1 || table > DataRecorder::kTables) {
    fail(s, GcsError::kNoRecordTable);
    return {};
  }
  if (option < 0 || option > 1000) {
    fail(s, GcsError::kNoRecordOption);
    return {};
  }
  accepted(s, recorder_.configure(static_cast<int>(table), args[1], static_cast<int>(option)));
  return {};
}

std::string GcsController::recorder_rate(Session& s, const Args& args) {
  if (args.size() != 1) {
    fail(s, GcsError::kParamCount);
    return {};
  }
  long long cycles = 0;
  if (!parse_integer(args[0], cycles)) {
    fail(s, GcsError::kParamSyntax);
    return {};
  }
  accepted(s, recorder_.set_rate(cycles));
  return {};
}

std::string GcsController::recorder_read(Session& s, const Args& args) {
  long long start = 1;
  long long count = -1;
  std::vector<int> tables;
  for (std::size_t i = 0; i < args.size(); ++i) {
    long long v = 0;
    if (!parse_integer(args[i], v)) {
      fail(s, GcsError::kParamSyntax);
      return {};
    }
    if (i == 0) {
      start = v;
    } else if (i == 1) {
      if (v < 0) {
        fail(s, GcsError::kParamOutOfRange);
        return {};
      }
      count = v;
    } else {
      tables.push_back(static_cast<int>(std::clamp<long long>(v, -1, 1000)));
    }
  }
  std::string answer;
  if (const GcsError e = recorder_.read(start, count, tables, servo_cycle_s_, answer);
      e != GcsError::kNone) {
    fail(s, e);
    return {};
  }
  return answer;
}

}  // namespace piezoshift::host
