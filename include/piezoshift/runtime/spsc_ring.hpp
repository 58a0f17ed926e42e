#pragma once
// Lock-free single-producer single-consumer ring buffer: the loop pushes one telemetry record per
// tick, the logging thread pops them. Capacity is fixed at construction (the only allocation).
//
//   try_push(x):  h = head (own), t = tail (acquire); full if h - t == capacity
//                 slot[h & mask] = x; head = h + 1 (release)        -> publishes the slot
//   try_pop(x):   t = tail (own), h = head (acquire); empty if h == t
//                 x = slot[t & mask]; tail = t + 1 (release)        -> frees the slot
// Indices run freely (64-bit, never wrap in practice); each side caches the other's index so that
// the shared cache line is read only when the cached value says full/empty.
//
// try_push/try_pop are real-time safe (no heap, no locks, no system calls) and wait-free. Exactly
// one thread may push and exactly one may pop.
#include <atomic>
#include <cstddef>
#include <memory>
#include <new>
#include <stdexcept>
#include <type_traits>

namespace piezoshift::runtime {

template <typename T>
class SpscRing {
  static_assert(std::is_trivially_copyable_v<T>, "records are copied bytewise between threads");
  static_assert(std::atomic<std::size_t>::is_always_lock_free);

 public:
  //! capacity must be a power of two (set-up; allocates).
  explicit SpscRing(std::size_t capacity)
      : slots_(new T[checked(capacity)]()), mask_(capacity - 1) {}
  SpscRing(const SpscRing&) = delete;
  SpscRing& operator=(const SpscRing&) = delete;

  //! Producer only. False (and nothing stored) when the ring is full.
  bool try_push(const T& value) noexcept {
    const std::size_t h = head_.load(std::memory_order_relaxed);
    if (h - tail_cache_ > mask_) {
      tail_cache_ = tail_.load(std::memory_order_acquire);
      if (h - tail_cache_ > mask_)
        return false;
    }
    slots_[h & mask_] = value;
    head_.store(h + 1, std::memory_order_release);
    return true;
  }

  //! Consumer only. False when the ring is empty.
  bool try_pop(T& value) noexcept {
    const std::size_t t = tail_.load(std::memory_order_relaxed);
    if (t == head_cache_) {
      head_cache_ = head_.load(std::memory_order_acquire);
      if (t == head_cache_)
        return false;
    }
    value = slots_[t & mask_];
    tail_.store(t + 1, std::memory_order_release);
    return true;
  }

  std::size_t capacity() const noexcept { return mask_ + 1; }
  //! Approximate when called while the other side runs.
  std::size_t size() const noexcept {
    return head_.load(std::memory_order_acquire) - tail_.load(std::memory_order_acquire);
  }

 private:
  static std::size_t checked(std::size_t capacity) {
    if (capacity < 2 || (capacity & (capacity - 1)) != 0)
      throw std::invalid_argument("SpscRing capacity must be a power of two >= 2");
    return capacity;
  }
  static constexpr std::size_t kLine = 64;  // keep producer and consumer state on separate lines
  std::unique_ptr<T[]> slots_;
  std::size_t mask_;
  alignas(kLine) std::atomic<std::size_t> head_{0};  // written by the producer
  std::size_t tail_cache_ = 0;                       // producer's copy of tail_
  alignas(kLine) std::atomic<std::size_t> tail_{0};  // written by the consumer
  std::size_t head_cache_ = 0;                       // consumer's copy of head_
};

}  // namespace piezoshift::runtime
