#pragma once
// Where the checkout and this build's piezoshift program are. Defined in one generated source
// (tests/CMakeLists.txt), not as compile definitions: an absolute path on every test's command
// line would make each test object differ between two clones, and the compiler cache (ccache,
// as CI uses it on a fresh clone) would miss them all.
#include <string>

namespace piezoshift::testing {

//! The source tree: configs/, fuzz/ and the like.
std::string source_dir();

//! The piezoshift program of this build (target piezoshift_cli).
std::string cli_path();

}  // namespace piezoshift::testing
