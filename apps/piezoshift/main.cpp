// The piezoshift command-line program: one subcommand per job (design, simulate, calibrate, ...).
#include <cstdio>
#include <exception>
#include <filesystem>

#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include "command.hpp"
#include "option_suggestion.hpp"
#include "piezoshift/core/input_error.hpp"
#include "piezoshift/rig/validity.hpp"

int main(int argc, char** argv) {
  CLI::App app;
  piezoshift::app::Action action;
  piezoshift::app::build_program(app, action);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    fmt::print(stderr, "piezoshift: error: {}\n", e.what());
    const std::string hint = piezoshift::app::option_suggestion(app, argc, argv);
    if (!hint.empty())
      fmt::print(stderr, "piezoshift: {}\n", hint);
    fmt::print(stderr, "Run with --help for more information.\n");
    return piezoshift::core::kExitBadInput;
  }

  try {
    return action ? action() : 0;
  } catch (const piezoshift::core::InputError& e) {
    fmt::print(stderr, "piezoshift: error: {}\n", e.what());
    return piezoshift::core::kExitBadInput;
  } catch (const std::filesystem::filesystem_error& e) {
    // Raised on a path the user named (an output folder under a file, no permission): bad input.
    fmt::print(stderr, "piezoshift: error: {}: {}\n", e.path1().string(), e.code().message());
    return piezoshift::core::kExitBadInput;
  } catch (const piezoshift::rig::ProcedureFailed& e) {
    fmt::print(stderr, "piezoshift: not valid: {}\n", e.what());
    return piezoshift::rig::kExitNotValid;
  } catch (const std::exception& e) {
    fmt::print(stderr, "piezoshift: internal error: {}\n", e.what());
    return 1;
  }
}
