#include "piezoshift/runtime/spsc_ring.hpp"

#include <cstdint>
#include <thread>

#include <gtest/gtest.h>

namespace piezoshift::runtime {
namespace {

struct Item {
  std::uint64_t seq;
  std::uint64_t check;  // seq * a constant: a torn copy shows as a mismatch
};

TEST(SpscRing, FullAndEmptyAtExactCapacity) {
  SpscRing<int> ring(4);
  int v = 0;
  EXPECT_FALSE(ring.try_pop(v));
  for (int i = 0; i < 4; ++i)
    EXPECT_TRUE(ring.try_push(i));
  EXPECT_FALSE(ring.try_push(99)) << "a full ring refuses, never overwrites";
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(ring.try_pop(v));
    EXPECT_EQ(v, i);
  }
  EXPECT_FALSE(ring.try_pop(v));
  // wrap around many times
  for (int i = 0; i < 1000; ++i) {
    ASSERT_TRUE(ring.try_push(i));
    ASSERT_TRUE(ring.try_pop(v));
    ASSERT_EQ(v, i);
  }
}

TEST(SpscRing, RejectsCapacityNotPowerOfTwo) {
  EXPECT_THROW(SpscRing<int>(3), std::invalid_argument);
  EXPECT_THROW(SpscRing<int>(0), std::invalid_argument);
}

// Two threads, a small ring so that both full and empty are hit constantly: every item arrives
// once, in order, intact.
TEST(SpscRing, TwoThreadsDeliverEveryItemInOrder) {
  constexpr std::uint64_t kItems = 1'000'000;
  constexpr std::uint64_t kMul = 0x9E3779B97F4A7C15ULL;
  SpscRing<Item> ring(64);
  std::uint64_t full_hits = 0;
  std::thread producer([&] {
    for (std::uint64_t i = 0; i < kItems; ++i) {
      while (!ring.try_push(Item{i, i * kMul}))
        ++full_hits;
    }
  });
  std::uint64_t expected = 0;
  std::uint64_t bad = 0;
  Item item{};
  while (expected < kItems) {
    if (ring.try_pop(item)) {
      if (item.seq != expected || item.check != expected * kMul)
        ++bad;
      ++expected;
    }
  }
  producer.join();
  EXPECT_EQ(bad, 0U);
  EXPECT_EQ(expected, kItems);
  EXPECT_FALSE(ring.try_pop(item));
}

}  // namespace
}  // namespace piezoshift::runtime
