#include "heap_peak.hpp"

#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <new>

namespace {
// Each block carries its size in front of it, so that operator delete can take it off again.
constexpr std::size_t kHeader = alignof(std::max_align_t);
std::atomic<std::size_t> g_live{0};
std::atomic<std::size_t> g_peak{0};

void raise_peak(std::size_t live) noexcept {
  std::size_t peak = g_peak.load();
  while (live > peak && !g_peak.compare_exchange_weak(peak, live)) {
  }
}
}  // namespace

namespace piezoshift::io::testing {
std::size_t heap_live_bytes() noexcept {
  return g_live.load();
}
void heap_reset_peak() noexcept {
  g_peak.store(g_live.load());
}
std::size_t heap_peak_bytes() noexcept {
  return g_peak.load();
}
}  // namespace piezoshift::io::testing

void* operator new(std::size_t n) {
  void* block = std::malloc(n + kHeader);
  if (block == nullptr)
    throw std::bad_alloc();
  *static_cast<std::size_t*>(block) = n;
  raise_peak(g_live.fetch_add(n) + n);
  return static_cast<char*>(block) + kHeader;
}
void operator delete(void* p) noexcept {
  if (p == nullptr)
    return;
  void* block = static_cast<char*>(p) - kHeader;
  g_live.fetch_sub(*static_cast<std::size_t*>(block));
  std::free(block);
}
void operator delete(void* p, std::size_t) noexcept {
  operator delete(p);
}
