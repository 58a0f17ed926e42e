#pragma once
// Counts heap allocations made by the calling thread between construction and stop(): the test
// executable replaces the global operator new (allocation_counter.cpp) to do it.
namespace piezoshift::runtime::testing {

void set_counting(bool on) noexcept;
long allocations() noexcept;

class AllocationCounter {
 public:
  AllocationCounter() noexcept : start_(allocations()) { set_counting(true); }
  ~AllocationCounter() { set_counting(false); }
  long stop() noexcept {
    set_counting(false);
    return allocations() - start_;
  }

 private:
  long start_;
};

}  // namespace piezoshift::runtime::testing
