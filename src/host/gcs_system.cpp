// The GCS commands that describe the controller and the session: identification, axes, units,
// ERR?, the command level and the fixed answers of #7 and #8.
#include "piezoshift/host/gcs_interpreter.hpp"

#include <fmt/core.h>

#include "gcs_arguments.hpp"

namespace piezoshift::host {

using namespace gcs;

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

std::string GcsInterpreter::error_number(Session& s, const Args&) {
  const int code = static_cast<int>(s.error);
  s.error = GcsError::kNone;
  return fmt::format("{}\n", code);
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

std::string GcsInterpreter::ready_query(Session&, const Args&) {
  return "\xB1\n";  // ready: PI answers the byte 0xB1
}

std::string GcsInterpreter::macro_query(Session&, const Args&) {
  return "0\n";  // no macros
}

}  // namespace piezoshift::host
