#include "command.hpp"

namespace piezoshift::app {

void build_program(CLI::App& app, Action& action) {
  app.description(
      "piezoshift: design, simulate, calibrate, run and validate a piezo phase shifter");
  app.require_subcommand(1);
  app.set_version_flag("--version", "piezoshift 0.1.0");
  add_design_command(app, action);
  add_simulate_command(app, action);
  add_fit_command(app, action);
  add_analyze_command(app, action);
  add_run_command(app, action);
  add_calibrate_command(app, action);
  add_serve_command(app, action);
  add_gcs_command(app, action);
  add_reproduce_command(app, action);
  add_compare_command(app, action);
  add_psi_command(app, action);
  add_measure_command(app, action);
  add_tolerance_command(app, action);
}

}  // namespace piezoshift::app
