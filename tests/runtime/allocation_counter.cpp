#include "allocation_counter.hpp"

#include <atomic>
#include <cstdlib>
#include <new>

namespace {
thread_local bool g_counting = false;
std::atomic<long> g_allocations{0};
}  // namespace

namespace piezoshift::runtime::testing {
void set_counting(bool on) noexcept {
  g_counting = on;
}
long allocations() noexcept {
  return g_allocations.load();
}
}  // namespace piezoshift::runtime::testing

void* operator new(std::size_t n) {
  if (g_counting)
    g_allocations.fetch_add(1);
  if (void* p = std::malloc(n == 0 ? 1 : n))
    return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
