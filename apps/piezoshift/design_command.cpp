// `piezoshift design`: the flexure design report (placeholder until the design module lands).
#include <fmt/core.h>

#include "command.hpp"
#include "piezoshift/design/flexure.hpp"

namespace piezoshift::app {

void add_design_command(CLI::App& app, Action& action) {
  CLI::App* cmd = app.add_subcommand("design", "Flexure design report (paper, Section 2)");
  cmd->callback([&action] {
    action = [] {
      const double km = design::mechanism_stiffness_N_per_um({}, {});
      fmt::print("mechanism_stiffness_N_per_um {:.3f}\n", km);
      return 0;
    };
  });
}

}  // namespace piezoshift::app
