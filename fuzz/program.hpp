#pragma once
// The piezoshift program's command line, as main() handles it (apps/piezoshift/main.cpp) but
// with every error main() would call internal (exit 1) let through as the exception: the fuzz
// targets treat that as a finding. Actions run checks only (app::work_begins, command.hpp): each
// stops where its costly work would begin.
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "command.hpp"

namespace piezoshift::fuzz {

//! How one command line ended.
enum class Outcome {
  kRefused,        //!< bad input: a CLI11 parse error (or --help), InputError, ProcedureFailed
  kStoppedAtWork,  //!< every check passed; the action stopped where its costly work begins
  kCompleted,      //!< the action ran to its end (it has no costly work for these options)
};

class Program {
 public:
  //! The program's own app (app::build_program).
  Program();
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;

  //! Parses args (args[0] is the program name) and runs the action up to its costly work. Bad
  //! input (a CLI11 parse error, core::InputError, ProcedureFailed) returns kRefused; any other
  //! exception propagates. Options keep what an earlier run() set when args do not set them
  //! again: run one Program more than once only with the same options.
  Outcome run(const std::vector<std::string>& args);

 private:
  CLI::App app_;
  app::Action action_;
};

}  // namespace piezoshift::fuzz
