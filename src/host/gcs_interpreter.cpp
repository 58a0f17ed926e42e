#include "piezoshift/host/gcs_interpreter.hpp"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <limits>
#include <thread>
#include <utility>

#include <fmt/core.h>

#include "piezoshift/runtime/safety_supervisor.hpp"

namespace piezoshift::host {

namespace {

using runtime::HostCommand;
constexpr std::size_t kGenerators = WaveGenerators::kGenerators;

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
  int base = 10;
  if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
    s.remove_prefix(2);  // GCS writes bit masks and parameter ids in hex: 0x101, 0x16000200
    base = 16;
  }
  const char* end = s.data() + s.size();
  const auto r = std::from_chars(s.data(), end, value, base);
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
  if (args.size() > GcsInterpreter::kMaxQueryItems)
    return GcsError::kParamCount;
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
  if (args.size() > GcsInterpreter::kMaxQueryItems)
    return GcsError::kParamCount;
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

// A "Z=..." line's value: v[a] with `digits` decimals.
auto fixed(const AxisValues& v, int digits) {
  return [&v, digits](std::size_t a) { return fmt::format("{:.{}f}", v[a], digits); };
}

// One "g=value" line per requested wave generator (1-based; all when none); value(g) 0-based.
template <typename Value>
GcsError generator_lines(const std::vector<std::string_view>& args, Value value,
                         std::string& answer) {
  const auto of = [&value](int g) { return value(static_cast<std::size_t>(g - 1)); };
  return id_lines(args, static_cast<int>(kGenerators), GcsError::kWaveIndex, of, answer);
}

// "{generator} {integer} ..." pairs with generators 1..n, each at most once (`WGO 1 1 1 0` says
// two things of one generator: refused as a syntax error, as a repeated axis is); kNone on
// success.
GcsError generator_pairs(const std::vector<std::string_view>& args, std::size_t n,
                         std::vector<WaveGenerators::Setting>& out) {
  if (args.empty() || args.size() % 2 != 0)
    return GcsError::kParamCount;
  for (std::size_t i = 0; i < args.size(); i += 2) {
    long long g = 0;
    long long v = 0;
    if (!parse_integer(args[i], g) || !parse_integer(args[i + 1], v))
      return GcsError::kParamSyntax;
    if (g < 1 || g > static_cast<long long>(n))
      return GcsError::kWaveIndex;
    const auto index = static_cast<std::size_t>(g - 1);
    for (const auto& [seen, value] : out) {
      if (seen == index)
        return GcsError::kParamSyntax;
    }
    out.emplace_back(index, v);
  }
  return GcsError::kNone;
}

}  // namespace

// The command lines, in docs/gcs.md's order; HLP? lists them as "{name} {syntax} - {help}".
const GcsInterpreter::Command GcsInterpreter::kCommands[] = {
    {"*IDN?", "", "identification", &GcsInterpreter::identification},
    {"CSV?", "", "GCS syntax version", &GcsInterpreter::syntax_version},
    {"SAI?", "[ALL]", "axis identifiers", &GcsInterpreter::axis_identifiers},
    {"CST?", "[{axis} ...]", "stage type of each axis", &GcsInterpreter::stage_types},
    {"PUN?", "[{axis} ...]", "position units", &GcsInterpreter::units},
    {"HLP?", "", "this list", &GcsInterpreter::help},
    {"ERR?", "", "the last error number (0: none since the last ERR?), reset to 0",
     &GcsInterpreter::error_number},
    {"CCL", "{level} [{password}]", "command level: 0, or 1 with the password advanced",
     &GcsInterpreter::command_level},
    {"CCL?", "", "command level", &GcsInterpreter::command_level_query},
    {"SVO", "{axis} {0|1} ...", "servo (semi-closed loop) off or on, all axes together",
     &GcsInterpreter::servo},
    {"SVO?", "[{axis} ...]", "servo state", &GcsInterpreter::servo_query},
    {"MOV", "{axis} {position} ...", "move to absolute position (servo on)",
     &GcsInterpreter::move_absolute},
    {"MVR", "{axis} {distance} ...", "move relative to the target (servo on)",
     &GcsInterpreter::move_relative},
    {"MOV?", "[{axis} ...]", "target position", &GcsInterpreter::target_query},
    {"POS?", "[{axis} ...]", "position from the strain gauges", &GcsInterpreter::position_query},
    {"ONT?", "[{axis} ...]", "on target", &GcsInterpreter::on_target_query},
    {"OVF?", "[{axis} ...]", "overflow: a PID at its limit, the target not held",
     &GcsInterpreter::overflow_query},
    {"STP", "", "stop: wave generators off, hold where the stage is (sets error 10)",
     &GcsInterpreter::stop},
    {"VEL", "{axis} {velocity} ...", "closed-loop velocity, stored (velocity control is off)",
     &GcsInterpreter::velocity},
    {"VEL?", "[{axis} ...]", "velocity", &GcsInterpreter::velocity_query},
    {"VCO?", "[{axis} ...]", "velocity control, 0", &GcsInterpreter::velocity_control_query},
    {"SPA?", "[{item} {parameter} ...]", "parameter values", &GcsInterpreter::parameters},
    {"SEP?", "[{item} {parameter} ...]", "parameter values, as SPA?", &GcsInterpreter::parameters},
    {"SPA", "{item} {parameter} {value} ...", "set the P or I term (CCL 1), applied bumplessly",
     &GcsInterpreter::set_parameters},
    {"HPA?", "", "parameter list", &GcsInterpreter::parameter_list},
    {"SVA", "{axis} {volts} ...", "open-loop value in amplifier volts (servo off)",
     &GcsInterpreter::open_loop},
    {"SVA?", "[{axis} ...]", "open-loop value", &GcsInterpreter::open_loop_query},
    {"VOL?", "[{channel} ...]", "amplifier output voltage of channel 1, 2, 3",
     &GcsInterpreter::voltage_query},
    {"TMN?", "[{axis} ...]", "lower travel limit", &GcsInterpreter::lower_limit_query},
    {"TMX?", "[{axis} ...]", "upper travel limit", &GcsInterpreter::upper_limit_query},
    {"DRC", "{table} {source} {option}", "record option of source in table",
     &GcsInterpreter::recorder_config},
    {"DRC?", "[{table} ...]", "record configuration", &GcsInterpreter::recorder_config_query},
    {"DRT", "{table} {source} [{value}]", "record trigger (0, 1: motion, 2: next command, 4: now)",
     &GcsInterpreter::recorder_trigger},
    {"DRT?", "[{table} ...]", "record trigger", &GcsInterpreter::recorder_trigger_query},
    {"RTR", "{cycles}", "record every n-th servo cycle", &GcsInterpreter::recorder_rate},
    {"RTR?", "", "record rate in servo cycles", &GcsInterpreter::recorder_rate_query},
    {"HDR?", "", "data recorder options, triggers and sizes", &GcsInterpreter::recorder_options},
    {"TNR?", "", "number of record tables", &GcsInterpreter::recorder_tables},
    {"DRL?", "[{table} ...]", "points recorded", &GcsInterpreter::recorder_length},
    {"DRR?", "[{start} [{count} [{table} ...]]]", "read recorded data",
     &GcsInterpreter::recorder_read},
    {"WAV", "{table} {X|&|+} {PNT|LIN|SIN_P} {parameters}", "define wave table 1 to 8",
     &GcsInterpreter::wave_define},
    {"WAV?", "[{table} {1} ...]", "number of points of the wave table",
     &GcsInterpreter::wave_query},
    {"WSL", "{generator} {table} ...", "wave table of wave generator 1 to 3 (axis Z, U, V)",
     &GcsInterpreter::wave_select},
    {"WSL?", "[{generator} ...]", "wave table of the generator",
     &GcsInterpreter::wave_select_query},
    {"WGC", "{generator} {cycles} ...", "cycles to play, 0: until stopped",
     &GcsInterpreter::wave_cycles},
    {"WGC?", "[{generator} ...]", "cycles", &GcsInterpreter::wave_cycles_query},
    {"WTR", "{generator} {rate} {0} ...", "servo cycles per table point (no interpolation)",
     &GcsInterpreter::wave_rate},
    {"WTR?", "[{generator} ...]", "table rate and interpolation", &GcsInterpreter::wave_rate_query},
    {"WGO", "{generator} {0|1} ...", "stop or start the generator (servo on)",
     &GcsInterpreter::wave_start},
    {"WGO?", "[{generator} ...]", "start mode", &GcsInterpreter::wave_start_query},
    {"WGR", "", "restart the recording", &GcsInterpreter::wave_record_restart},
    {"TWG?", "", "number of wave generators, 3", &GcsInterpreter::wave_generators},
};

// The single-character commands, after the command lines in HLP?.
const GcsInterpreter::Immediate GcsInterpreter::kImmediates[] = {
    {5, "#5", "moving axes as a hex bit mask", &GcsInterpreter::moving_query},
    {7, "#7", "ready (0xB1)", &GcsInterpreter::ready_query},
    {8, "#8", "macro running (0)", &GcsInterpreter::macro_query},
    {9, "#9", "running wave generators as a hex bit mask", &GcsInterpreter::wave_running_query},
    {24, "#24", "stop all, as STP", &GcsInterpreter::stop},
};

std::vector<std::string_view> GcsInterpreter::command_names() {
  std::vector<std::string_view> names;
  for (const Command& c : kCommands)
    names.push_back(c.name);
  for (const Immediate& c : kImmediates)
    names.push_back(c.name);
  return names;
}

GcsInterpreter::GcsInterpreter(const StageModel& model, runtime::HostLink& link,
                               double servo_cycle_s, const GcsOptions& options)
    : model_(model),
      link_(link),
      servo_cycle_s_(servo_cycle_s),
      options_(options),
      settle_samples_(static_cast<std::uint64_t>(
          std::max(1.0, std::round(options.settle_time_s / servo_cycle_s)))),
      servo_params_(model.params().controller, servo_cycle_s) {
  position_ = model_.pose_from_sgs(Vec3{});
}

std::string default_identification(const std::string& daq) {
  return fmt::format(
      "(c)2026 piezoshift, E-727 compatible semi-closed-loop PZT phase shifter{}, "
      "0, 0.1.0",
      daq.empty() ? std::string{} : fmt::format(" ({})", daq));
}

void GcsInterpreter::on_connect(ClientId client) {
  sessions_[client] = Session{};
  // A PI controller keeps its error until ERR? reads it, whoever connects: a fault latched
  // before this client came is its first error too.
  if (faulted_)
    sessions_[client].error = GcsError::kMotionError;
}

void GcsInterpreter::on_disconnect(ClientId client) {
  sessions_.erase(client);
}

void GcsInterpreter::fail(Session& session, GcsError error) {
  ++stats_.errors;
  session.error = error;  // PI keeps only the last error
}

std::string GcsInterpreter::on_overlong_line(ClientId client) {
  fail(sessions_[client], GcsError::kCommandTooLong);
  return {};
}

bool GcsInterpreter::answer_pending(ClientId client) const {
  const auto it = sessions_.find(client);
  return it != sessions_.end() && it->second.reading.pending();
}

std::string GcsInterpreter::more_answer(ClientId client) {
  std::string part;
  DataRecorder::continue_read(sessions_[client].reading, part, DataRecorder::kValuesPerPart);
  stats_.answer_bytes += part.size();
  return part;
}

std::string GcsInterpreter::on_line(ClientId client, std::string_view line) {
  drain();
  ++stats_.lines;
  Session& session = sessions_[client];
  session.reading = {};  // an answer not taken whole is dropped
  std::vector<std::string_view> tokens = split(line);
  if (tokens.empty())
    return {};
  const std::string_view name = tokens.front();
  tokens.erase(tokens.begin());
  std::string answer = execute(session, name, tokens);
  stats_.answer_bytes += answer.size();
  trigger_.line_done(name, sequence_);
  // A query that failed answers one empty line: a client reading up to the answer's last LF
  // never waits in vain, and finds the reason with ERR? (PIPython does so after every query).
  if (answer.empty() && name.back() == '?')
    return std::string(1, '\n');  // (not `answer = "\n"`: GCC 12 warns -Wrestrict wrongly)
  return answer;
}

bool GcsInterpreter::is_immediate(char byte) const {
  return std::any_of(std::begin(kImmediates), std::end(kImmediates),
                     [byte](const Immediate& c) { return c.byte == byte; });
}

std::string GcsInterpreter::on_immediate(ClientId client, char byte) {
  drain();
  ++stats_.lines;
  Session& session = sessions_[client];
  for (const Immediate& c : kImmediates) {
    if (c.byte == byte)
      return (this->*c.handler)(session, {});
  }
  return {};
}

std::string GcsInterpreter::execute(Session& s, std::string_view name, const Args& args) {
  for (const Command& c : kCommands) {
    if (c.name != name)
      continue;
    if (c.syntax.empty() && !args.empty()) {
      fail(s, GcsError::kParamCount);
      return {};
    }
    return (this->*c.handler)(s, args);
  }
  fail(s, GcsError::kUnknownCommand);
  return {};
}

bool GcsInterpreter::send(Session& session, HostCommand command) {
  command.sequence = ++sequence_;
  if (!link_.commands.try_push(command)) {
    fail(session, GcsError::kCommunication);
    return false;
  }
  ++stats_.commands_sent;
  return true;
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

bool GcsInterpreter::slot_free(std::size_t g) {
  for (int i = 0; i < 50 && !waves_.applied(g, last_.applied_sequence); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    drain();
  }
  return waves_.applied(g, last_.applied_sequence);
}

bool GcsInterpreter::stop_waves(Session& s) {
  for (std::size_t g = 0; g < kGenerators; ++g)
    if (waves_.active(g) && !stop_wave(s, g))
      return false;
  return true;
}

bool GcsInterpreter::stop_wave(Session& s, std::size_t g) {
  const AxisValues now = commanded();
  if (!send(s, WaveGenerators::stop_command(g)))
    return false;
  if (waves_.running(g)) {
    target_[g] = now[g];  // where the loop folds it, to within the ticks until it applies this
    measured_target_[g] = false;
  }
  waves_.stopped(g, sequence_);
  return true;
}

void GcsInterpreter::drain() {
  runtime::HostSample s{};
  while (link_.samples.try_pop(s))
    take(s);
}

void GcsInterpreter::take(const runtime::HostSample& s) {
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
  // The loop refused SPA's set (configure_problem): the running set is the one before it.
  if (configure_sequence_ != 0 && s.applied_sequence >= configure_sequence_) {
    if (s.configure_problem != 0)
      servo_params_.applied(before_configure_);
    configure_sequence_ = 0;
  }

  // A generator the loop reports stopped (its cycles done, WGO 0, servo off, a fault) leaves
  // its axis where the wave ended: that is the target from now on.
  if (const unsigned finished = waves_.update(s.applied_sequence, s.wave_running); finished != 0) {
    const AxisValues ended = model_.pose_from_points(s.zd_um);
    for (std::size_t g = 0; g < kGenerators; ++g)
      if (((finished >> g) & 1u) != 0) {
        target_[g] = ended[g];
        measured_target_[g] = false;
      }
  }
  const AxisValues target = commanded();

  position_ = model_.pose_from_sgs(s.sgs_V);
  const bool counting =
      servo_on_ && !faulted && s.closed_loop != 0 && s.applied_sequence >= move_sequence_;
  std::array<bool, 3> off_target{};
  for (std::size_t a = 0; a < 3; ++a) {
    const double tol = a == 0 ? options_.on_target_tolerance_um : options_.on_target_tolerance_urad;
    off_target[a] = !(std::fabs(position_[a] - target[a]) <= tol);
    settled_[a] = counting && !waves_.running(a) && !off_target[a] ? settled_[a] + 1 : 0;
  }
  overflow_.update(s.closed_loop != 0, s.saturated_mask, off_target);

  if (!trigger_.records(s.applied_sequence))
    return;  // from before the command that started this recording took effect
  RecorderInput in{};
  in.target = target;
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

bool GcsInterpreter::accepted(Session& s, GcsError error) {
  if (error == GcsError::kNone)
    return true;
  fail(s, error);
  return false;
}

std::string GcsInterpreter::reply(Session& s, GcsError error, std::string& answer) {
  return accepted(s, error) ? std::move(answer) : std::string{};
}

void GcsInterpreter::hold_applied_volts() {
  open_loop_V_ = model_.open_loop_for(model_.channel_V_from_daq(last_.ao_V));
}

std::string GcsInterpreter::identification(Session&, const Args&) {
  return options_.identification + "\n";
}

std::string GcsInterpreter::syntax_version(Session&, const Args&) {
  return "2.0\n";
}

std::string GcsInterpreter::axis_identifiers(Session& s, const Args& args) {
  if (args.size() > 1 || (args.size() == 1 && args[0] != "ALL")) {
    fail(s, GcsError::kParamSyntax);
    return {};
  }
  return framed({"Z", "U", "V"});
}

std::string GcsInterpreter::stage_types(Session& s, const Args& args) {
  std::string answer;
  const auto stage = [](std::size_t) { return std::string{"PIEZOSHIFT_TRIPOD"}; };
  return reply(s, axis_lines(args, stage, answer), answer);
}

std::string GcsInterpreter::units(Session& s, const Args& args) {
  std::string answer;
  const auto unit = [](std::size_t a) { return axis_unit(kAxes[a]); };
  return reply(s, axis_lines(args, unit, answer), answer);
}

std::string GcsInterpreter::help(Session&, const Args&) {
  std::vector<std::string> lines{"The following commands are valid:"};
  for (const Command& c : kCommands) {
    lines.push_back(c.syntax.empty() ? fmt::format("{} - {}", c.name, c.help)
                                     : fmt::format("{} {} - {}", c.name, c.syntax, c.help));
  }
  for (const Immediate& c : kImmediates)
    lines.push_back(fmt::format("{} - {}", c.name, c.help));
  lines.emplace_back("Axes: Z piston (um), U tip theta_x (urad), V tilt theta_y (urad)");
  return framed(lines);
}

std::string GcsInterpreter::error_number(Session& s, const Args&) {
  const int code = static_cast<int>(s.error);
  s.error = GcsError::kNone;
  return fmt::format("{}\n", code);
}

std::string GcsInterpreter::servo_query(Session& s, const Args& args) {
  std::string answer;
  const auto servo = [this](std::size_t) { return servo_on_ ? 1 : 0; };
  return reply(s, axis_lines(args, servo, answer), answer);
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

std::string GcsInterpreter::moving_query(Session&, const Args&) {
  return fmt::format("{:X}\n", moving_mask());
}

std::string GcsInterpreter::ready_query(Session&, const Args&) {
  return "\xB1\n";  // ready: PI answers the byte 0xB1
}

std::string GcsInterpreter::macro_query(Session&, const Args&) {
  return "0\n";  // no macros
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

std::string GcsInterpreter::parameter_list(Session&, const Args&) {
  std::vector<std::string> lines;
  for (const ServoParameter& p : ServoParameters::list())
    lines.push_back(
        fmt::format("0x{:08X}=\t0\t1\t{}\t{}\t{}", p.id, p.type, p.group, p.description));
  return framed(lines);
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

std::string GcsInterpreter::recorder_config_query(Session& s, const Args& args) {
  std::string answer;
  const auto table = [this](int t) { return recorder_.describe_table(t); };
  return reply(s, id_lines(args, DataRecorder::kTables, GcsError::kNoRecordTable, table, answer),
               answer);
}

std::string GcsInterpreter::recorder_trigger_query(Session& s, const Args& args) {
  std::string answer;
  const auto trigger = [this](int) { return fmt::format("{} 0", trigger_.source()); };
  return reply(s, id_lines(args, DataRecorder::kTables, GcsError::kNoRecordTable, trigger, answer),
               answer);
}

std::string GcsInterpreter::recorder_rate_query(Session&, const Args&) {
  return fmt::format("{}\n", recorder_.rate());
}

std::string GcsInterpreter::recorder_options(Session&, const Args&) {
  return framed(
      {"#RecordOptions", "0=Nothing is recorded", "1=Commanded position of axis",
       "2=Actual position of axis", "3=Position error of axis", "7=Piezo voltage of output channel",
       "17=Sensor (strain gauge) of input channel, um of actuator stroke",
       "90=Interferometer position of axis (piezoshift; NaN on hardware)", "#TriggerOptions",
       "0=Default setting: any command changing the position",
       "1=Any command changing the position (MOV, MVR, SVA, SVO, STP, WGO)",
       "2=Next command, then the default again", "4=Immediately", "#Parameters to be set with SPA",
       "none: the recorder is set with DRC, DRT, RTR", "#Additional information",
       fmt::format("{} datarecorder tables", DataRecorder::kTables),
       fmt::format("{} datapoints per table", DataRecorder::kPoints), "end of help"});
}

std::string GcsInterpreter::recorder_tables(Session&, const Args&) {
  return fmt::format("{}\n", DataRecorder::kTables);
}

std::string GcsInterpreter::recorder_length(Session& s, const Args& args) {
  std::string answer;
  const auto points = [this](int t) {
    return recorder_.describe_table(t) != "0 0" ? recorder_.points() : 0;
  };
  return reply(s, id_lines(args, DataRecorder::kTables, GcsError::kNoRecordTable, points, answer),
               answer);
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
// `MOV Z` to TMN? or TMX? alone is reached (issue 30). A tilt a client set is never changed.
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

std::string GcsInterpreter::recorder_config(Session& s, const Args& args) {
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

std::string GcsInterpreter::recorder_rate(Session& s, const Args& args) {
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

std::string GcsInterpreter::recorder_read(Session& s, const Args& args) {
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
    } else if (tables.size() <= static_cast<std::size_t>(DataRecorder::kTables)) {
      // More than kTables names hold a repeat or a table that does not exist, which the first
      // kTables + 1 already show: a longer list costs no memory (every name is still parsed).
      tables.push_back(static_cast<int>(std::clamp<long long>(v, -1, 1000)));
    }
  }
  std::string answer;
  if (const GcsError e =
          recorder_.start_read(start, count, tables, servo_cycle_s_, answer, s.reading);
      e != GcsError::kNone) {
    fail(s, e);
    return {};
  }
  DataRecorder::continue_read(s.reading, answer, DataRecorder::kValuesPerPart);
  return answer;
}

std::string GcsInterpreter::recorder_trigger(Session& s, const Args& args) {
  // "DRT {table} {source}" (PIPython with one trigger for all: table 0) or triples with a value.
  const std::size_t step = args.size() == 2 ? 2 : 3;
  if (args.empty() || args.size() % step != 0) {
    fail(s, GcsError::kParamCount);
    return {};
  }
  int source = trigger_.source();
  for (std::size_t i = 0; i < args.size(); i += step) {
    long long table = 0;
    long long src = 0;
    if (!parse_integer(args[i], table) || !parse_integer(args[i + 1], src)) {
      fail(s, GcsError::kParamSyntax);
      return {};
    }
    if (table < 0 || table > DataRecorder::kTables) {
      fail(s, GcsError::kNoRecordTable);
      return {};
    }
    if (!RecordTrigger::is_source(src)) {
      fail(s, GcsError::kParamOutOfRange);
      return {};
    }
    source = static_cast<int>(src);  // one trigger serves all tables (they share one clock)
  }
  trigger_.set_source(source, sequence_);
  return {};
}

std::string GcsInterpreter::parameters(Session& s, const Args& args) {
  std::vector<std::string> lines;
  if (args.empty()) {
    for (const ServoParameter& p : ServoParameters::list())
      lines.push_back(fmt::format("1 0x{:08X}={}", p.id, servo_params_.value(p.id)));
    return framed(lines);
  }
  if (args.size() % 2 != 0 || args.size() > 2 * kMaxQueryItems) {
    fail(s, GcsError::kParamCount);
    return {};
  }
  for (std::size_t i = 0; i < args.size(); i += 2) {
    long long id = 0;
    if (!parse_integer(args[i + 1], id)) {
      fail(s, GcsError::kParamSyntax);
      return {};
    }
    const std::string v = servo_params_.value(id);
    if (v.empty()) {
      fail(s, GcsError::kUnknownParameter);
      return {};
    }
    lines.push_back(fmt::format("{} 0x{:08X}={}", args[i], id, v));
  }
  return framed(lines);
}

// SPA {item} {id} {value} ...: every write checked first, then the set they make (nothing changes
// when one fails), then one parameter set to the loop through its one parameter path
// (kConfigure), applied between two ticks and bumplessly (ControlCycle::try_configure).
std::string GcsInterpreter::set_parameters(Session& s, const Args& args) {
  if (args.empty() || args.size() % 3 != 0) {
    fail(s, GcsError::kParamCount);
    return {};
  }
  const control::SemiClosedLoopParams before = servo_params_.controller();
  ServoParameters next = servo_params_;
  for (std::size_t i = 0; i < args.size(); i += 3) {
    long long id = 0;
    double value = 0.0;
    if (!parse_integer(args[i + 1], id)) {
      fail(s, GcsError::kParamSyntax);
      return {};
    }
    if (!parse_real(args[i + 2], value)) {
      fail(s, GcsError::kInvalidReal);
      return {};
    }
    control::SemiClosedLoopParams written{};
    if (!accepted(s, next.write(id, value, s.command_level, written)))
      return {};
    next.applied(written);
  }
  if (!accepted(s, next.check(next.controller())))
    return {};  // 17: the whole set, as a calibration file is checked
  if (!link_.params.try_push(next.controller())) {
    fail(s, GcsError::kCommunication);
    return {};
  }
  HostCommand c{};
  c.kind = HostCommand::Kind::kConfigure;
  if (!send(s, c))
    return {};  // 52: the loop takes no commands (a full ring); its set waits in `params`
  before_configure_ = before;
  configure_sequence_ = sequence_;
  servo_params_ = next;
  return {};
}

std::string GcsInterpreter::command_level(Session& s, const Args& args) {
  long long level = 0;
  if (args.empty() || args.size() > 2 || !parse_integer(args[0], level)) {
    fail(s, args.empty() || args.size() > 2 ? GcsError::kParamCount : GcsError::kParamSyntax);
    return {};
  }
  if (level != 0 && level != 1) {
    fail(s, GcsError::kParamOutOfRange);
    return {};
  }
  if (level == 1 && (args.size() != 2 || args[1] != ServoParameters::kAdvancedPassword)) {
    fail(s, GcsError::kInvalidPassword);
    return {};
  }
  s.command_level = static_cast<int>(level);
  return {};
}

std::string GcsInterpreter::command_level_query(Session& s, const Args&) {
  return fmt::format("{}\n", s.command_level);
}

// A PID at its limit while the axis is on target (at rest at the bottom of the travel) is no
// overflow: overflow_monitor.hpp.
std::string GcsInterpreter::overflow_query(Session& s, const Args& args) {
  std::string answer;
  const auto value = [this](std::size_t a) { return overflow_.overflow(a) ? 1 : 0; };
  return reply(s, axis_lines(args, value, answer), answer);
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

std::string GcsInterpreter::wave_define(Session& s, const Args& args) {
  if (args.size() < 3) {
    fail(s, GcsError::kParamCount);
    return {};
  }
  long long table = 0;
  if (!parse_integer(args[0], table)) {
    fail(s, GcsError::kParamSyntax);
    return {};
  }
  const int t = static_cast<int>(std::clamp<long long>(table, -1, 1000));
  accepted(s, waves_.define(t, Args(args.begin() + 1, args.end())));
  return {};
}

std::string GcsInterpreter::wave_query(Session& s, const Args& args) {
  std::vector<std::string> lines;
  const auto line = [&](int t) {
    lines.push_back(fmt::format("{} 1={}", t, waves_.tables().values(t).size()));
  };
  if (args.empty()) {
    for (int t = 1; t <= WaveTables::kTables; ++t)
      line(t);
    return framed(lines);
  }
  if (args.size() % 2 != 0 || args.size() > 2 * kMaxQueryItems) {
    fail(s, GcsError::kParamCount);
    return {};
  }
  for (std::size_t i = 0; i < args.size(); i += 2) {
    long long t = 0;
    long long param = 0;
    if (!parse_integer(args[i], t) || !parse_integer(args[i + 1], param)) {
      fail(s, GcsError::kParamSyntax);
      return {};
    }
    if (t < 1 || t > WaveTables::kTables) {
      fail(s, GcsError::kWaveIndex);
      return {};
    }
    if (param != 1) {  // 1: the number of points, the one parameter PI defines for WAV?
      fail(s, GcsError::kParamOutOfRange);
      return {};
    }
    line(static_cast<int>(t));
  }
  return framed(lines);
}

std::string GcsInterpreter::wave_select(Session& s, const Args& args) {
  std::vector<WaveGenerators::Setting> tables;
  if (accepted(s, generator_pairs(args, kGenerators, tables)))
    accepted(s, waves_.select(tables));
  return {};
}

std::string GcsInterpreter::wave_select_query(Session& s, const Args& args) {
  std::string answer;
  const auto table = [this](std::size_t g) { return fmt::format("{}", waves_.table(g)); };
  return reply(s, generator_lines(args, table, answer), answer);
}

std::string GcsInterpreter::wave_cycles(Session& s, const Args& args) {
  std::vector<WaveGenerators::Setting> cycles;
  if (accepted(s, generator_pairs(args, kGenerators, cycles)))
    accepted(s, waves_.set_cycles(cycles));
  return {};
}

std::string GcsInterpreter::wave_cycles_query(Session& s, const Args& args) {
  std::string answer;
  const auto cycles = [this](std::size_t g) { return fmt::format("{}", waves_.cycles(g)); };
  return reply(s, generator_lines(args, cycles, answer), answer);
}

std::string GcsInterpreter::wave_rate(Session& s, const Args& args) {
  // "{generator} {rate} {interpolation}" triples; generator 0: all.
  if (args.empty() || args.size() % 3 != 0) {
    fail(s, GcsError::kParamCount);
    return {};
  }
  std::vector<std::pair<std::size_t, long long>> set;
  for (std::size_t i = 0; i < args.size(); i += 3) {
    long long g = 0;
    long long rate = 0;
    long long interpolation = 0;
    if (!parse_integer(args[i], g) || !parse_integer(args[i + 1], rate) ||
        !parse_integer(args[i + 2], interpolation)) {
      fail(s, GcsError::kParamSyntax);
      return {};
    }
    if (g < 0 || g > static_cast<long long>(kGenerators)) {
      fail(s, GcsError::kWaveIndex);
      return {};
    }
    if (!accepted(s, WaveGenerators::check_rate(rate, interpolation)))
      return {};
    for (std::size_t k = 0; k < kGenerators; ++k)
      if (g == 0 || static_cast<std::size_t>(g - 1) == k)
        set.emplace_back(k, rate);
  }
  for (const auto& [g, rate] : set)
    waves_.set_rate(g, rate);
  return {};
}

std::string GcsInterpreter::wave_rate_query(Session& s, const Args& args) {
  std::string answer;
  const auto rate = [this](std::size_t g) { return fmt::format("{} 0", waves_.rate(g)); };
  return reply(s, generator_lines(args, rate, answer), answer);
}

std::string GcsInterpreter::wave_start(Session& s, const Args& args) {
  std::vector<WaveGenerators::Setting> pairs;
  if (!accepted(s, generator_pairs(args, kGenerators, pairs)))
    return {};
  std::array<bool, kGenerators> start{};
  for (const auto& [g, mode] : pairs) {
    if (mode != 0 && mode != 1) {  // 1: start now; PI's other bits (triggers, offsets) are not here
      fail(s, GcsError::kWgoBitNotSupported);
      return {};
    }
    start[g] = mode == 1;
  }
  const bool any_start = std::find(start.begin(), start.end(), true) != start.end();
  if (any_start) {
    if (!servo_on_ || faulted_) {
      fail(s, GcsError::kServoOff);
      return {};
    }
    if (!accepted(s, waves_.check_start(start, commanded())))
      return {};
  }
  for (const auto& [g, mode] : pairs) {
    const bool done = mode == 0 ? !waves_.active(g) || stop_wave(s, g) : start_wave(s, g, mode);
    if (!done)
      return {};
  }
  if (any_start) {
    settled_ = {};
    trigger_.motion(sequence_);
  }
  return {};
}

bool GcsInterpreter::start_wave(Session& s, std::size_t g, long long mode) {
  // The slot the loop does not read is free once it has applied g's last start or stop.
  if (!slot_free(g)) {
    fail(s, GcsError::kCommunication);
    return false;
  }
  if (!send(s, waves_.start_command(g, target_[g])))
    return false;
  waves_.started(g, mode, sequence_);
  return true;
}

std::string GcsInterpreter::wave_start_query(Session& s, const Args& args) {
  std::string answer;
  const auto mode = [this](std::size_t g) { return fmt::format("{}", waves_.mode(g)); };
  return reply(s, generator_lines(args, mode, answer), answer);
}

std::string GcsInterpreter::wave_running_query(Session&, const Args&) {
  return fmt::format("{:X}\n", waves_.running_mask());
}

std::string GcsInterpreter::wave_record_restart(Session&, const Args&) {
  trigger_.restart(sequence_);
  return {};
}

std::string GcsInterpreter::wave_generators(Session&, const Args&) {
  return fmt::format("{}\n", kGenerators);
}

}  // namespace piezoshift::host
