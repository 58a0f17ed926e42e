#include "piezoshift/instrument/hold_summary.hpp"

#include <algorithm>
#include <cmath>

namespace piezoshift::instrument {

namespace {

std::optional<double> second_means_rms_nm(const std::vector<ExposureRecord>& hold,
                                          const std::vector<double>& path) {
  if (path.empty())
    return std::nullopt;
  const double t0 = hold.front().trigger_time_s;
  std::vector<double> sum, count;
  for (std::size_t i = 0; i < path.size(); ++i) {
    const auto k = static_cast<std::size_t>(hold[i].trigger_time_s - t0);
    if (k >= sum.size()) {
      sum.resize(k + 1, 0.0);
      count.resize(k + 1, 0.0);
    }
    sum[k] += path[i];
    count[k] += 1.0;
  }
  double sq = 0.0;
  std::size_t n = 0;
  for (std::size_t k = 0; k + 1 < sum.size(); ++k)  // the last second is not whole
    if (count[k] > 0.0) {
      sq += (sum[k] / count[k]) * (sum[k] / count[k]);
      ++n;
    }
  if (n == 0)
    return std::nullopt;
  return std::sqrt(sq / static_cast<double>(n));
}

}  // namespace

HoldSummary hold_summary(const SequenceResult& result) {
  const std::vector<ExposureRecord>& hold = result.hold;
  HoldSummary s;
  s.frames = hold.size();
  if (hold.size() >= 2) {
    s.span_s = hold.back().trigger_time_s - hold.front().trigger_time_s;
    s.frame_interval_s = s.span_s / static_cast<double>(hold.size() - 1);
  }
  s.path_error_nm = path_errors_nm(result, hold);
  if (!s.path_error_nm.empty()) {
    double sum = 0.0, worst = 0.0;
    for (double d : s.path_error_nm) {
      sum += d * d;
      worst = std::max(worst, std::fabs(d));
    }
    s.path_error_rms_nm = std::sqrt(sum / static_cast<double>(s.path_error_nm.size()));
    s.path_error_max_nm = worst;
  }
  s.path_error_1s_means_rms_nm = second_means_rms_nm(hold, s.path_error_nm);
  for (const ExposureRecord& e : hold)
    if (!e.lock_state.empty())
      ++s.lock_states[e.lock_state];
  return s;
}

}  // namespace piezoshift::instrument
