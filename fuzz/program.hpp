#pragma once
// The piezoshift program's command line, as main() handles it (apps/piezoshift/main.cpp) but
// with every error main() would call internal (exit 1) let through as the exception: the fuzz
// targets treat that as a finding.
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "command.hpp"

namespace piezoshift::fuzz {

//! Decides, after a successful parse, whether the selected subcommand's action runs.
using MayRun = bool (*)(const CLI::App& app);

class Program {
 public:
  //! The program's own app (app::build_program).
  Program();
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;

  //! Parses args (args[0] is the program name); runs the action when may_run says so. Bad input
  //! (a CLI11 parse error, core::InputError, ProcedureFailed) returns; any other exception
  //! propagates. Options keep what an earlier
  //! run() set when args do not set them again: run one Program more than once only with the
  //! same options.
  void run(const std::vector<std::string>& args, MayRun may_run);

 private:
  CLI::App app_;
  app::Action action_;
};

}  // namespace piezoshift::fuzz
