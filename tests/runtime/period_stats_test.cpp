#include "piezoshift/runtime/period_stats.hpp"

#include <gtest/gtest.h>

namespace piezoshift::runtime {
namespace {

TEST(DurationHistogram, NearestRankPercentilesOfOneToThousandMicroseconds) {
  DurationHistogram h;                // 100 ns bins
  for (int us = 1000; us >= 1; --us)  // order must not matter
    h.record(us * 1000);
  EXPECT_EQ(h.count(), 1000U);
  EXPECT_EQ(h.percentile_ns(0.50), 500'000);
  EXPECT_EQ(h.percentile_ns(0.99), 990'000);
  EXPECT_EQ(h.percentile_ns(0.999), 999'000);
  EXPECT_EQ(h.percentile_ns(1.0), 1'000'000);
  EXPECT_EQ(h.percentile_ns(0.0), 1'000);
  EXPECT_EQ(h.max_ns(), 1'000'000);
  EXPECT_DOUBLE_EQ(h.mean_ns(), 500'500.0);
}

TEST(DurationHistogram, OffGridValuesReadAtMostOneBinLow) {
  DurationHistogram h;
  h.record(12'345);
  EXPECT_EQ(h.percentile_ns(0.5), 12'300);
  EXPECT_EQ(h.max_ns(), 12'345);
}

TEST(DurationHistogram, OverflowReportsExactMaximum) {
  DurationHistogram h(100, 1'000'000);
  for (int i = 0; i < 998; ++i)
    h.record(1'000);
  h.record(5'000'000);
  h.record(7'654'321);
  EXPECT_EQ(h.percentile_ns(0.5), 1'000);
  EXPECT_EQ(h.percentile_ns(0.999), 7'654'321) << "rank 999 lands in the overflow bin";
  EXPECT_EQ(h.max_ns(), 7'654'321);
  h.record(-5);
  EXPECT_EQ(h.percentile_ns(0.0), 0) << "negative durations count as 0";
}

TEST(LoopStats, PeriodErrorLatencyAndOverruns) {
  LoopStats s;
  const std::int64_t T = 1'000'000;
  // tick 0: on time; tick 1: woke 30 us late; tick 2: on time but worked 1.2 T (overrun);
  // tick 3 (re-phased after a skipped slot): on time, short
  EXPECT_FALSE(s.record(0, 0, 100'000, 0, T));
  EXPECT_FALSE(s.record(T, T + 30'000, T + 130'000, 0, T));
  EXPECT_TRUE(s.record(2 * T, 2 * T, 2 * T + 1'200'000, T + 30'000, T));
  EXPECT_FALSE(s.record(4 * T, 4 * T, 4 * T + 50'000, 2 * T, T));
  EXPECT_EQ(s.ticks, 4U);
  EXPECT_EQ(s.overruns, 1U);
  EXPECT_EQ(s.max_consecutive_overruns, 1U);
  EXPECT_EQ(s.wake_latency.max_ns(), 30'000);
  // period errors: |1.03 T - T| = 30 us, |0.97 T - T| = 30 us, |2 T - T| = 1000 us
  EXPECT_EQ(s.period_error.count(), 3U);
  EXPECT_EQ(s.period_error.percentile_ns(0.5), 30'000);
  EXPECT_EQ(s.period_error.max_ns(), 1'000'000);
  EXPECT_EQ(s.compute.max_ns(), 1'200'000);
}

}  // namespace
}  // namespace piezoshift::runtime
