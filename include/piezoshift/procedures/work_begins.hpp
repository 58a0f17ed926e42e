#pragma once
// Where a procedure's costly work begins, for checks-only runs (the fuzz targets, docs/fuzzing.md).

namespace piezoshift::procedures {

//! Thrown by work_begins() when the program checks only.
struct WorkNotRun {};

//! Called by every procedure where its costly work begins: after its options, the files they
//! name and its cost estimate are checked, before it simulates, calibrates, serves, connects,
//! opens a device, analyses frames or writes a file. It returns at once unless
//! set_checks_only(true) (the fuzz targets, fuzz/program.hpp), when it throws WorkNotRun, so that
//! every subcommand's input is checked in milliseconds (docs/fuzzing.md lists where each stops).
void work_begins();
void set_checks_only(bool checks_only);

}  // namespace piezoshift::procedures
