#pragma once
// Internal errors that issue 17 lists by name and that another branch (`bounds`) fixes at their
// root; until that lands they are not reported again, so that `make fuzz` keeps looking for new
// ones instead of stopping at the first known one. Each entry is the start of the exception's
// message; delete it (and this list, when empty) once its fix is merged, and add its reproducer
// to fuzz/regressions/.
#include <exception>

namespace piezoshift::fuzz {

bool is_known_finding(const std::exception& e);

}  // namespace piezoshift::fuzz
