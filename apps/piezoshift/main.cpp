// The piezoshift command-line program: one subcommand per job (design, simulate, calibrate, ...).
#include <cstdio>
#include <exception>
#include <filesystem>

#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include "command.hpp"
#include "piezoshift/experiments/validity.hpp"
#include "piezoshift/io/input_error.hpp"

int main(int argc, char** argv) {
  CLI::App app{"piezoshift: design, simulate, calibrate, run and validate a piezo phase shifter"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "piezoshift 0.1.0");

  piezoshift::app::Action action;
  piezoshift::app::add_design_command(app, action);
  piezoshift::app::add_simulate_command(app, action);
  piezoshift::app::add_fit_command(app, action);
  piezoshift::app::add_analyze_command(app, action);
  piezoshift::app::add_run_command(app, action);
  piezoshift::app::add_calibrate_command(app, action);
  piezoshift::app::add_serve_command(app, action);
  piezoshift::app::add_gcs_command(app, action);
  piezoshift::app::add_reproduce_command(app, action);
  piezoshift::app::add_psi_command(app, action);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return piezoshift::io::kExitBadInput;
  }

  try {
    return action ? action() : 0;
  } catch (const piezoshift::io::InputError& e) {
    fmt::print(stderr, "piezoshift: error: {}\n", e.what());
    return piezoshift::io::kExitBadInput;
  } catch (const std::filesystem::filesystem_error& e) {
    // Raised on a path the user named (an output folder under a file, no permission): bad input.
    fmt::print(stderr, "piezoshift: error: {}: {}\n", e.path1().string(), e.code().message());
    return piezoshift::io::kExitBadInput;
  } catch (const piezoshift::experiments::ProcedureFailed& e) {
    fmt::print(stderr, "piezoshift: not valid: {}\n", e.what());
    return piezoshift::experiments::kExitNotValid;
  } catch (const std::exception& e) {
    fmt::print(stderr, "piezoshift: internal error: {}\n", e.what());
    return 1;
  }
}
