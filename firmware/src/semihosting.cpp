#include "semihosting.hpp"

#include <cstring>

namespace piezoshift::firmware {
namespace {

// Operation numbers of the ARM semihosting specification.
constexpr int kSysOpen = 0x01;
constexpr int kSysClose = 0x02;
constexpr int kSysWrite = 0x05;
constexpr int kSysGetCmdline = 0x15;
constexpr int kSysExitExtended = 0x20;
constexpr std::uint32_t kAdpStoppedApplicationExit = 0x20026;

int call(int op, const void* arg) noexcept {
  register int r0 asm("r0") = op;
  register const void* r1 asm("r1") = arg;
  asm volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
  return r0;
}

}  // namespace

int semihosting_open(const char* path, bool write_binary) noexcept {
  // fopen modes by index: 4 = "w", 5 = "wb"; ":tt" with "w" is the console.
  const std::uint32_t args[3] = {reinterpret_cast<std::uint32_t>(path), write_binary ? 5U : 4U,
                                 static_cast<std::uint32_t>(std::strlen(path))};
  return call(kSysOpen, args);
}

void semihosting_close(int handle) noexcept {
  const std::uint32_t args[1] = {static_cast<std::uint32_t>(handle)};
  call(kSysClose, args);
}

bool semihosting_write(int handle, const void* data, std::size_t bytes) noexcept {
  const std::uint32_t args[3] = {static_cast<std::uint32_t>(handle),
                                 reinterpret_cast<std::uint32_t>(data), bytes};
  return call(kSysWrite, args) == 0;  // returns the number of bytes NOT written
}

bool semihosting_command_line(char* buffer, std::size_t bytes) noexcept {
  std::uint32_t args[2] = {reinterpret_cast<std::uint32_t>(buffer), bytes};
  return call(kSysGetCmdline, args) == 0;
}

void HostFile::write(const void* data, std::size_t bytes) noexcept {
  const auto* p = static_cast<const unsigned char*>(data);
  while (bytes > 0) {
    const std::size_t n = bytes < sizeof buffer_ - used_ ? bytes : sizeof buffer_ - used_;
    std::memcpy(buffer_ + used_, p, n);
    used_ += n;
    p += n;
    bytes -= n;
    if (used_ == sizeof buffer_)
      flush();
  }
}

void HostFile::text(const char* s) noexcept {
  write(s, std::strlen(s));
}

void HostFile::number(std::uint64_t value) noexcept {
  char digits[20];
  std::size_t n = 0;
  do {
    digits[n++] = static_cast<char>('0' + value % 10);
    value /= 10;
  } while (value != 0);
  char out[20];
  for (std::size_t i = 0; i < n; ++i)
    out[i] = digits[n - 1 - i];
  write(out, n);
}

void HostFile::flush() noexcept {
  if (used_ > 0 && handle_ >= 0 && !semihosting_write(handle_, buffer_, used_))
    failed_ = true;
  used_ = 0;
}

void HostFile::close() noexcept {
  flush();
  if (handle_ >= 0)
    semihosting_close(handle_);
  handle_ = -1;
}

}  // namespace piezoshift::firmware

extern "C" void semihosting_exit(int status) {
  // SYS_EXIT_EXTENDED carries the exit status through to QEMU's own exit code.
  const std::uint32_t args[2] = {piezoshift::firmware::kAdpStoppedApplicationExit,
                                 static_cast<std::uint32_t>(status)};
  piezoshift::firmware::call(piezoshift::firmware::kSysExitExtended, args);
  for (;;) {
  }
}
