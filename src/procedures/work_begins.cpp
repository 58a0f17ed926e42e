#include "piezoshift/procedures/work_begins.hpp"

#include <atomic>

namespace piezoshift::procedures {

namespace {
std::atomic<bool> g_checks_only{false};
}  // namespace

void work_begins() {
  if (g_checks_only.load(std::memory_order_relaxed))
    throw WorkNotRun{};
}

void set_checks_only(bool checks_only) {
  g_checks_only.store(checks_only, std::memory_order_relaxed);
}

}  // namespace piezoshift::procedures
