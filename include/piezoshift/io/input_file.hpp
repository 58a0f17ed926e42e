#pragma once
// Reading a user's input file (configuration, calibration, data) whole, in bounded time and
// memory: only a regular file is read, and only up to a size limit. A directory used to read as
// an empty file (its keys silently defaulted), and /dev/zero or a FIFO was read until memory ran
// out. Each refusal throws core::InputError naming the path and the reason.
#include <cstdint>
#include <string>

namespace piezoshift::io {

//! Configuration and calibration files (TOML): configs/paper.toml is 8 KB.
inline constexpr std::uintmax_t kMaxConfigFileBytes = 1u << 20;  // 1 MiB
//! Data files (CSV): a day of 1 kHz samples of four columns is about 50 MB.
inline constexpr std::uintmax_t kMaxDataFileBytes = 64u << 20;  // 64 MiB
//! Frame stacks (.npy): 16 frames of 2048 x 2048 doubles.
inline constexpr std::uintmax_t kMaxFrameFileBytes = 512u << 20;  // 512 MiB

//! The bytes of the regular file at path, at most max_bytes of them. A directory, a device, a
//! FIFO or a socket, a file that cannot be opened or read, or one larger than max_bytes (also
//! one that grows past it while read) throws InputError.
std::string read_input_file(const std::string& path, std::uintmax_t max_bytes);

}  // namespace piezoshift::io
