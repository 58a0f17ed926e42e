#pragma once
// "did you mean --config?" for an option the command does not have (`design --cfg x`): the
// closest long option of the subcommand given, by edit distance (at most 2) or as an
// abbreviation (its letters in order, the first one first).
#include <string>

#include <CLI/CLI.hpp>

namespace piezoshift::app {

//! The hint for the first unknown long option in argv, or "" when there is none or nothing close.
std::string option_suggestion(const CLI::App& app, int argc, const char* const* argv);

}  // namespace piezoshift::app
