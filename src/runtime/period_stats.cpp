#include "piezoshift/runtime/period_stats.hpp"

#include <cmath>
#include <stdexcept>

namespace piezoshift::runtime {

DurationHistogram::DurationHistogram(std::int64_t bin_ns, std::int64_t range_ns) : bin_ns_(bin_ns) {
  if (bin_ns <= 0 || range_ns < bin_ns)
    throw std::invalid_argument("DurationHistogram: need 0 < bin_ns <= range_ns");
  bins_.assign(static_cast<std::size_t>(range_ns / bin_ns) + 1, 0U);
}

void DurationHistogram::record(std::int64_t duration_ns) noexcept {
  if (duration_ns < 0)
    duration_ns = 0;
  const std::size_t last = bins_.size() - 1;
  const auto index = static_cast<std::size_t>(duration_ns / bin_ns_);
  ++bins_[index < last ? index : last];
  ++count_;
  sum_ns_ += static_cast<double>(duration_ns);
  if (duration_ns > max_ns_)
    max_ns_ = duration_ns;
}

void DurationHistogram::clear() noexcept {
  for (auto& b : bins_)
    b = 0;
  count_ = 0;
  max_ns_ = 0;
  sum_ns_ = 0.0;
}

double DurationHistogram::mean_ns() const noexcept {
  return count_ == 0 ? 0.0 : sum_ns_ / static_cast<double>(count_);
}

std::int64_t DurationHistogram::percentile_ns(double q) const noexcept {
  if (count_ == 0)
    return 0;
  if (!(q > 0.0))
    q = 0.0;
  if (q > 1.0)
    q = 1.0;
  // nearest rank: the smallest value with at least ceil(q n) samples at or below it (rank >= 1)
  auto rank = static_cast<std::uint64_t>(std::ceil(q * static_cast<double>(count_)));
  if (rank == 0)
    rank = 1;
  std::uint64_t cumulative = 0;
  const std::size_t last = bins_.size() - 1;
  for (std::size_t i = 0; i < last; ++i) {
    cumulative += bins_[i];
    if (cumulative >= rank)
      return static_cast<std::int64_t>(i) * bin_ns_;
  }
  return max_ns_;  // in the overflow bin
}

void LoopStats::clear() noexcept {
  period_error.clear();
  wake_latency.clear();
  compute.clear();
  ticks = overruns = max_consecutive_overruns = consecutive_overruns = skipped_slots = 0;
}

bool LoopStats::record(std::int64_t deadline_ns, std::int64_t wake_ns, std::int64_t end_ns,
                       std::int64_t previous_wake_ns, std::int64_t period_ns) noexcept {
  wake_latency.record(wake_ns - deadline_ns);
  if (ticks > 0) {
    const std::int64_t error = (wake_ns - previous_wake_ns) - period_ns;
    period_error.record(error < 0 ? -error : error);
  }
  compute.record(end_ns - wake_ns);
  ++ticks;
  const bool overrun = end_ns - deadline_ns > period_ns;
  if (overrun) {
    ++overruns;
    ++consecutive_overruns;
    if (consecutive_overruns > max_consecutive_overruns)
      max_consecutive_overruns = consecutive_overruns;
  } else {
    consecutive_overruns = 0;
  }
  return overrun;
}

}  // namespace piezoshift::runtime
