#pragma once
// The fuzz targets' entry points (docs/fuzzing.md): each takes one input as bytes and feeds it to
// piezoshift the way a user's file, command line or socket would. An entry returns normally
// when the input was handled, accepted or refused as bad input (core::InputError, a GCS error, a
// CLI11 parse error); anything else is a finding: an exception escapes (libFuzzer reports the
// std::terminate as a crash, the replay test as a failure), a sanitizer fires, the input takes
// longer than a second or more than 512 MB.
//
// libFuzzer binaries (fuzz/fuzz_target.cpp, preset `fuzz`) and the replay test of the normal
// suite (tests/fuzz, also under `make sanitize`) call the same functions.
#include <span>
#include <string_view>

#include "program.hpp"

namespace piezoshift::fuzz {

//! The project configuration (configs/paper.toml's format: design and twin sections), read
//! from a file holding the input as config::load_project_config reads `--config`.
void config_input(std::string_view data);
//! Recorded data as a CSV file, through each path that reads one: `analyze linearity`,
//! `analyze repeatability`, `analyze step`, `fit matrix` and `fit poly` (the program's own
//! subcommands, --json).
void csv_input(std::string_view data);
//! A calibration file as `run`, `serve` and `simulate --calibration` read it.
void calibration_input(std::string_view data);
//! A GCS session: the input split at LF into lines fed to host::GcsInterpreter on the twin's
//! stage model, with a stand-in loop thread that applies every command and answers with samples.
//! A first line that host::looks_like_http ends it, as LineServer closes such a connection.
void gcs_input(std::string_view data);
//! The body of serve's POST /api/measure through app::check_measure_request: what it accepts must
//! be within sequence_problem's, the travel's and the memory bound; a refusal is 400 or 413 with
//! its reason.
void measure_request_input(std::string_view data);
//! The texts of a figure (file name, titles, labels; fields at NUL) through io::check_output_path
//! and io::write_plot_files: none may reach gnuplot's command stream (plot_entry.cpp).
void plot_input(std::string_view data);
//! A command line, one argument per input line, parsed by the program's own CLI11 app, and the
//! selected subcommand's action run up to its costly work (app::work_begins): every subcommand's
//! checks run, none simulates, serves, connects or writes (docs/fuzzing.md).
void command_line_input(std::string_view data);
//! command_line_input, saying how the input ended (the budget test, tests/fuzz).
Outcome command_line(std::string_view data);

struct Target {
  const char* name;  //!< fuzz/corpus/<name>, fuzz/regressions/<name>, build target fuzz_<name>
  void (*entry)(std::string_view);
};
//! Every target above.
std::span<const Target> targets();

}  // namespace piezoshift::fuzz
