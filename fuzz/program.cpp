#include "program.hpp"

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/rig/validity.hpp"

namespace piezoshift::fuzz {

Program::Program() {
  app::build_program(app_, action_);
}

Outcome Program::run(const std::vector<std::string>& args) {
  std::vector<std::string> storage = args;  // argv is char*, CLI11 does not write through it
  std::vector<char*> argv;
  for (std::string& a : storage)
    argv.push_back(a.data());
  app_.clear();
  action_ = {};
  try {
    app_.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::Error&) {  // --help, --version and every parse error: main() exits 0 or 2
    return Outcome::kRefused;
  }
  if (!action_)
    return Outcome::kCompleted;
  // Set for every action, never cleared: no fuzz input may start a costly work.
  app::set_checks_only(true);
  try {
    action_();
  } catch (const app::WorkNotRun&) {
    return Outcome::kStoppedAtWork;
  } catch (const core::InputError&) {
    return Outcome::kRefused;
  } catch (const rig::ProcedureFailed&) {
    return Outcome::kRefused;
  }
  return Outcome::kCompleted;
}

}  // namespace piezoshift::fuzz
