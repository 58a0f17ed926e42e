#pragma once
// ARM semihosting (the debugger, here QEMU, services `bkpt 0xab`): the firmware's only I/O under
// emulation. A real board replaces it with its UART or USB link (docs/mcu.md).
#include <cstddef>
#include <cstdint>

namespace piezoshift::firmware {

//! A host file handle, or -1.
int semihosting_open(const char* path, bool write_binary) noexcept;
void semihosting_close(int handle) noexcept;
//! Writes all of data; false on error.
bool semihosting_write(int handle, const void* data, std::size_t bytes) noexcept;
//! The command line QEMU was given (-semihosting-config arg=...), NUL-terminated; false if none.
bool semihosting_command_line(char* buffer, std::size_t bytes) noexcept;

//! Buffered text and binary output to one handle (flushes when full and on flush()).
class HostFile {
 public:
  explicit HostFile(int handle) noexcept : handle_(handle) {}
  bool ok() const noexcept { return handle_ >= 0 && !failed_; }
  void write(const void* data, std::size_t bytes) noexcept;
  void text(const char* s) noexcept;
  void number(std::uint64_t value) noexcept;
  void flush() noexcept;
  //! Flushes and closes the handle.
  void close() noexcept;

 private:
  int handle_;
  bool failed_ = false;
  std::size_t used_ = 0;
  unsigned char buffer_[4096] = {};
};

}  // namespace piezoshift::firmware

extern "C" void semihosting_exit(int status);
