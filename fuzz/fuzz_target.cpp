// One libFuzzer binary per entry point: PIEZOSHIFT_FUZZ_ENTRY names the function (fuzz/CMakeLists).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "entry_points.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  PIEZOSHIFT_FUZZ_ENTRY(std::string_view(reinterpret_cast<const char*>(data), size));
  return 0;
}
