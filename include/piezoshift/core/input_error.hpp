#pragma once
// The one exception type for bad user input (configuration files, data files, command-line
// values). Its message names the file, the key or line and column, and the reason; the CLI
// prints it and exits with status 2.
#include <stdexcept>
#include <string>

namespace piezoshift::core {

class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

//! Exit status for bad input (configuration, data, command line).
inline constexpr int kExitBadInput = 2;

}  // namespace piezoshift::core
