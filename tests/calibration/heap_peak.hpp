#pragma once
// The most heap memory live at once (through operator new) since a HeapPeak was made, above
// what was live then: the test executable replaces the global operator new (heap_peak.cpp) to
// keep the count. A number of bytes, not a time: it does not depend on the machine's load.
#include <cstddef>

namespace piezoshift::io::testing {

std::size_t heap_live_bytes() noexcept;
//! Starts a new peak at the bytes live now.
void heap_reset_peak() noexcept;
std::size_t heap_peak_bytes() noexcept;

class HeapPeak {
 public:
  HeapPeak() noexcept : start_(heap_live_bytes()) { heap_reset_peak(); }
  //! The peak since construction above the bytes live then.
  std::size_t bytes() const noexcept {
    const std::size_t peak = heap_peak_bytes();
    return peak > start_ ? peak - start_ : 0;
  }

 private:
  std::size_t start_;
};

}  // namespace piezoshift::io::testing
