// `piezoshift gcs`: a small GCS 2.0 command-line client for `piezoshift serve` (or any GCS 2.0
// controller on TCP): sends each command in turn, prints the answers of the queries, and after
// each command asks ERR? on the same connection, as PIPython does in its default mode.
// "#5", "#7", "#8", "#9" and "#24" are sent as GCS's single-character commands (the byte alone).
//
// Exit status: 0 every command succeeded; 3 the controller reported a GCS error (stderr names
// the command, the error number and PI's text; the commands after it are not sent); 2 the server
// cannot be reached or stops answering (the message names host:port).
#include <charconv>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "command.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/host/gcs_client.hpp"
#include "piezoshift/host/gcs_error.hpp"

namespace piezoshift::app {

namespace {

struct GcsClientOptions {
  std::string host = "127.0.0.1";
  int port = 50000;
  double timeout_s = 5.0;
  bool transcript = false;
  std::vector<std::string> commands;
};

// Exit status for a GCS error the controller reported.
constexpr int kGcsErrorExit = 3;

// "#5" -> the byte 5 (GCS single-character commands); 0 for anything else.
char single_character(const std::string& command) {
  if (command == "#5" || command == "#7" || command == "#8" || command == "#9" || command == "#24")
    return static_cast<char>(std::stoi(command.substr(1)));
  return 0;
}

// An answer for printing: #7's one byte 0xB1 as "0xB1" (it is not text).
std::string printable(const std::string& answer) {
  if (answer.size() == 2 && static_cast<unsigned char>(answer[0]) >= 0x80)
    return fmt::format("0x{:02X}\n", static_cast<unsigned char>(answer[0]));
  return answer;
}

// ERR?'s answer as a number; a server that answers something else is not a GCS controller.
int error_number(const std::string& answer) {
  int value = 0;
  const char* end = answer.data() + answer.size() - (answer.ends_with('\n') ? 1 : 0);
  const auto r = std::from_chars(answer.data(), end, value);
  if (r.ec != std::errc{} || r.ptr != end || answer.empty())
    throw std::runtime_error(fmt::format("unexpected answer to ERR?: \"{}\"", answer));
  return value;
}

int gcs(const GcsClientOptions& o) {
  if (o.port < 1 || o.port > 65535)
    throw core::InputError(fmt::format("--port {}: must be 1 to 65535", o.port));
  if (!(o.timeout_s > 0.0))
    throw core::InputError(fmt::format("--timeout-s {}: must be > 0 s", o.timeout_s));
  work_begins();  // the connection
  try {
    host::GcsClient client(o.host, static_cast<std::uint16_t>(o.port), o.timeout_s);
    for (const std::string& command : o.commands) {
      if (o.transcript)
        fmt::print("> {}\n", command);
      const char byte = single_character(command);
      // In GCS every query, and only a query, ends its name with '?'; of the single-character
      // commands, all but #24 (stop) answer.
      const std::string name = command.substr(0, command.find(' '));
      const bool answers = byte != 0 ? byte != 24 : !name.empty() && name.back() == '?';
      if (byte != 0)
        client.send_raw(std::string(1, byte));
      else
        client.send(command);
      if (answers)
        fmt::print("{}", printable(client.read_answer()));
      if (name == "ERR?")
        continue;  // the error it read is the answer; asking again would hide it
      const int error = error_number(client.query("ERR?"));
      if (error != 0) {
        std::fflush(stdout);
        fmt::print(stderr, "piezoshift gcs: {}: GCS error {}: {}\n", command, error,
                   host::describe(static_cast<host::GcsError>(error)));
        return kGcsErrorExit;
      }
      // A command that answers nothing still says it was done, on stderr: stdout keeps only
      // the answers, for scripts.
      if (!answers)
        fmt::print(stderr, "piezoshift gcs: {}: done (ERR? 0)\n", printable(command));
    }
  } catch (const std::runtime_error& e) {
    throw core::InputError(e.what());
  }
  return 0;
}

}  // namespace

void add_gcs_command(CLI::App& app, Action& action) {
  auto o = std::make_shared<GcsClientOptions>();
  CLI::App* cmd = app.add_subcommand(
      "gcs", "Send GCS 2.0 commands to `piezoshift serve` and print the answers (docs/gcs.md)");
  cmd->add_option("commands", o->commands, "commands, one per argument (quote each)")->required();
  cmd->add_option("--host", o->host, "server address")->capture_default_str();
  cmd->add_option("--port", o->port, "server port")->capture_default_str();
  cmd->add_option("--timeout-s", o->timeout_s, "wait this long for an answer (s)")
      ->capture_default_str();
  cmd->add_flag("--transcript", o->transcript, "print each command before its answer");
  cmd->callback([&action, o] { action = [o] { return gcs(*o); }; });
}

}  // namespace piezoshift::app
