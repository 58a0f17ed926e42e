// The GCS parameter commands: SPA?/SEP?, SPA (the P and I terms, bumplessly) and HPA?.
#include "piezoshift/host/gcs_interpreter.hpp"

#include <fmt/core.h>

#include "gcs_arguments.hpp"

namespace piezoshift::host {

using namespace gcs;

namespace {

using runtime::HostCommand;

}  // namespace

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

std::string GcsInterpreter::parameter_list(Session&, const Args&) {
  std::vector<std::string> lines;
  for (const ServoParameter& p : ServoParameters::list())
    lines.push_back(
        fmt::format("0x{:08X}=\t0\t1\t{}\t{}\t{}", p.id, p.type, p.group, p.description));
  return framed(lines);
}

}  // namespace piezoshift::host
