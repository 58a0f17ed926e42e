#include "program.hpp"

#include "piezoshift/core/input_error.hpp"
#include "piezoshift/rig/validity.hpp"

namespace piezoshift::fuzz {

Program::Program() {
  app::build_program(app_, action_);
}

void Program::run(const std::vector<std::string>& args, MayRun may_run) {
  std::vector<std::string> storage = args;  // argv is char*, CLI11 does not write through it
  std::vector<char*> argv;
  for (std::string& a : storage)
    argv.push_back(a.data());
  app_.clear();
  action_ = {};
  try {
    app_.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::Error&) {  // --help, --version and every parse error: main() exits 0 or 2
    return;
  }
  if (!action_ || !may_run(app_))
    return;
  try {
    action_();
  } catch (const core::InputError&) {
  } catch (const rig::ProcedureFailed&) {
  }
}

}  // namespace piezoshift::fuzz
