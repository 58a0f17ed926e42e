#pragma once
// How a subcommand plugs into the piezoshift program: add_*_command() declares the subcommand and
// its options on the CLI11 app; when CLI11 selects it, its callback stores the action to run.
// main() runs that action once parsing is complete, inside the one place that maps errors to exit
// statuses (bad input: 2). One file per subcommand: <name>_command.cpp.
#include <functional>

#include <CLI/CLI.hpp>

#include "piezoshift/procedures/work_begins.hpp"

namespace piezoshift::app {

//! Exit status of a command whose loop stopped on a latched fault, or whose outputs could not be
//! brought to 0 V (docs/runtime.md).
inline constexpr int kExitFault = 3;

using Action = std::function<int()>;

void add_design_command(CLI::App& app, Action& action);     // design_command.cpp
void add_simulate_command(CLI::App& app, Action& action);   // simulate_command.cpp
void add_fit_command(CLI::App& app, Action& action);        // fit_command.cpp
void add_analyze_command(CLI::App& app, Action& action);    // analyze_command.cpp
void add_run_command(CLI::App& app, Action& action);        // run_command.cpp
void add_reproduce_command(CLI::App& app, Action& action);  // reproduce_command.cpp
void add_compare_command(CLI::App& app, Action& action);    // compare_command.cpp
void add_calibrate_command(CLI::App& app, Action& action);  // calibrate_command.cpp
void add_serve_command(CLI::App& app, Action& action);      // serve_command.cpp
void add_gcs_command(CLI::App& app, Action& action);        // gcs_command.cpp
void add_psi_command(CLI::App& app, Action& action);        // psi_command.cpp
void add_measure_command(CLI::App& app, Action& action);    // measure_command.cpp
void add_tolerance_command(CLI::App& app, Action& action);  // tolerance_command.cpp

// Where each action's costly work begins (procedures/work_begins.hpp).
using procedures::set_checks_only;
using procedures::work_begins;
using procedures::WorkNotRun;

//! The whole program on an empty app: its description, --version and every subcommand above
//! (commands.cpp). main() and the command-line fuzz target (fuzz/) build the same app.
void build_program(CLI::App& app, Action& action);

}  // namespace piezoshift::app
