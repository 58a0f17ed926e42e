#pragma once
// Loop timing statistics, recorded in the loop without allocating:
//
//   DurationHistogram  fixed bins of bin_ns (default 100 ns) from 0 to range_ns (default 10 ms),
//                      one overflow bin, exact count / max / sum. percentile_ns(q) is the nearest
//                      rank: the lower edge of the first bin whose cumulative count reaches
//                      ceil(q n), so it is exact for data on the bin grid and at most one bin low
//                      otherwise; in the overflow bin it is the exact maximum.
//
//   LoopStats, per tick k with scheduled deadline D_k, wake-up W_k and end of work E_k:
//     wake_latency_k  = W_k - D_k                          (cyclictest's "latency")
//     period_error_k  = | (W_k - W_{k-1}) - T |            (k >= 1; T the nominal period)
//     compute_k       = E_k - W_k                          (read + controller + supervisor + write)
//     overrun_k       = E_k - D_k > T                      (the next deadline was missed)
//
// record() and the queries are real-time safe; the constructor allocates.
#include <cstdint>
#include <vector>

namespace piezoshift::runtime {

class DurationHistogram {
 public:
  explicit DurationHistogram(std::int64_t bin_ns = 100, std::int64_t range_ns = 10'000'000);

  //! Negative durations count as 0.
  void record(std::int64_t duration_ns) noexcept;
  void clear() noexcept;

  std::uint64_t count() const noexcept { return count_; }
  std::int64_t max_ns() const noexcept { return max_ns_; }
  double mean_ns() const noexcept;
  //! Nearest-rank percentile, q in [0, 1]; 0 when empty.
  std::int64_t percentile_ns(double q) const noexcept;
  std::int64_t bin_ns() const noexcept { return bin_ns_; }

 private:
  std::int64_t bin_ns_;
  std::vector<std::uint32_t> bins_;  // last bin = overflow
  std::uint64_t count_ = 0;
  std::int64_t max_ns_ = 0;
  double sum_ns_ = 0.0;
};

struct LoopStats {
  DurationHistogram period_error;
  DurationHistogram wake_latency;
  DurationHistogram compute;
  std::uint64_t ticks = 0;
  std::uint64_t overruns = 0;
  std::uint64_t max_consecutive_overruns = 0;
  std::uint64_t consecutive_overruns = 0;
  std::uint64_t skipped_slots = 0;  //!< deadlines given up after overruns (re-phasing)

  void clear() noexcept;
  //! One tick's timing (see the header comment); returns whether it overran.
  bool record(std::int64_t deadline_ns, std::int64_t wake_ns, std::int64_t end_ns,
              std::int64_t previous_wake_ns, std::int64_t period_ns) noexcept;
};

}  // namespace piezoshift::runtime
