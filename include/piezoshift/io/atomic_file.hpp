#pragma once
// Replacing a file so that a reader (or a crash) sees the old content or the new, never a mix:
//   write contents to "<dir>/.<name>.tmp.<pid>", fsync it, rename() over path, fsync the
//   directory (so the rename itself survives a power cut).
// Used for calibration files: a half-written calibration would silently mis-drive the stage.
// A writer killed mid-write (SIGKILL) leaves its temporary file; the next write of the same file
// removes every such "<dir>/.<name>.tmp.<pid>" whose process no longer exists.
// Set-up only (does I/O); throws core::InputError naming the path and the reason; the temporary
// file is removed on failure and the old file is left untouched.
#include <string>
#include <string_view>

namespace piezoshift::io {

void write_file_atomically(const std::string& path, std::string_view contents);

}  // namespace piezoshift::io
