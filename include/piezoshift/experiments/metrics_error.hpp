#pragma once
// Recorded data that a performance metric cannot be computed from (too few samples, a zero span
// or step, a non-finite value, mismatched sizes). Bad user input, so a core::InputError (exit 2
// in the CLI); the message names the metric and the problem, the caller adds the file.
#include <string>

#include "piezoshift/core/input_error.hpp"

namespace piezoshift::experiments {

class MetricsError : public core::InputError {
 public:
  explicit MetricsError(const std::string& message) : core::InputError(message) {}
};

}  // namespace piezoshift::experiments
