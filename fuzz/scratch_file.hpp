#pragma once
// A file holding one fuzz input, for the readers that take a path (as the program's users give
// one): one per process and name in the temporary directory, rewritten for every input, removed
// at exit.
#include <string>
#include <string_view>

namespace piezoshift::fuzz {

//! Writes data to this process's scratch file called name (e.g. "data.csv") and returns its path.
std::string scratch_file(std::string_view name, std::string_view data);

}  // namespace piezoshift::fuzz
