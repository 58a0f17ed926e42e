// The GCS interpreter's command table, its dispatch, the clients' sessions and what the loop
// reports (docs/gcs.md); the commands themselves are in gcs_system, gcs_motion, gcs_parameters,
// gcs_data_recorder and gcs_wave_generator.cpp.
#include "piezoshift/host/gcs_interpreter.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <fmt/core.h>

#include "gcs_arguments.hpp"
#include "piezoshift/runtime/safety_supervisor.hpp"

namespace piezoshift::host {

using namespace gcs;

namespace {

using runtime::HostCommand;
constexpr std::size_t kGenerators = WaveGenerators::kGenerators;

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

// HLP? answers the command table itself, so the list cannot drift from the dispatch.
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

}  // namespace piezoshift::host
