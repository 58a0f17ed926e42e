// `piezoshift gcs`: a small GCS 2.0 command-line client for `piezoshift serve` (or any GCS 2.0
// controller on TCP): sends each command in turn and prints the answers of the queries.
//
// Exit status: 0 every command was sent and every query answered; 2 the server cannot be reached
// or stops answering (the message names host:port).
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "command.hpp"
#include "piezoshift/host/gcs_client.hpp"
#include "piezoshift/io/input_error.hpp"

namespace piezoshift::app {

namespace {

struct GcsClientOptions {
  std::string host = "127.0.0.1";
  int port = 50000;
  double timeout_s = 5.0;
  bool transcript = false;
  std::vector<std::string> commands;
};

int gcs(const GcsClientOptions& o) {
  if (o.port < 1 || o.port > 65535)
    throw io::InputError(fmt::format("--port {}: must be 1 to 65535", o.port));
  if (!(o.timeout_s > 0.0))
    throw io::InputError(fmt::format("--timeout-s {}: must be > 0 s", o.timeout_s));
  try {
    host::GcsClient client(o.host, static_cast<std::uint16_t>(o.port), o.timeout_s);
    for (const std::string& command : o.commands) {
      if (o.transcript)
        fmt::print("> {}\n", command);
      client.send(command);
      // In GCS every query, and only a query, ends its name with '?'.
      const std::string name = command.substr(0, command.find(' '));
      if (!name.empty() && name.back() == '?')
        fmt::print("{}", client.read_answer());
    }
  } catch (const std::runtime_error& e) {
    throw io::InputError(e.what());
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
