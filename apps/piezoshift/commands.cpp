#include "command.hpp"

#include <atomic>

namespace piezoshift::app {

namespace {
std::atomic<bool> g_checks_only{false};
}  // namespace

void work_begins() {
  if (g_checks_only.load(std::memory_order_relaxed))
    throw WorkNotRun{};
}

void set_checks_only(bool checks_only) {
  g_checks_only.store(checks_only, std::memory_order_relaxed);
}

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
