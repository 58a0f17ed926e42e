#include "piezoshift/io/input_error.hpp"

// The io module's first source; TOML, CSV and JSON readers and writers live beside it.
namespace piezoshift::io {}  // namespace piezoshift::io
