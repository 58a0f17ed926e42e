// `piezoshift fit`: placeholder, being written.
#include "command.hpp"

namespace piezoshift::app {

void add_fit_command(CLI::App& app, Action& action) {
  CLI::App* cmd = app.add_subcommand("fit", "(not yet available)");
  cmd->callback([&action] { action = [] { return 1; }; });
}

}  // namespace piezoshift::app
