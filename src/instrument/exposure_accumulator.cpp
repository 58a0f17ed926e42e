#include "piezoshift/instrument/exposure_accumulator.hpp"

#include <algorithm>
#include <cmath>

namespace piezoshift::instrument {

void ExposureAccumulator::begin(const camera::PlatePose& first) noexcept {
  *this = ExposureAccumulator{};
  piston_sum_ = 0.5 * first.piston_nm;
  tip_sum_ = 0.5 * first.theta_x_urad;
  tilt_sum_ = 0.5 * first.theta_y_urad;
  lo_ = hi_ = first.piston_nm;
  last_ = first;
}

void ExposureAccumulator::add(const std::array<double, 3>& error_nm,
                              const camera::PlatePose& q) noexcept {
  ++n_;
  for (std::size_t i = 0; i < 3; ++i) {
    error_sum_[i] += error_nm[i];
    error_max_nm_ = std::max(error_max_nm_, std::fabs(error_nm[i]));
  }
  piston_sum_ += q.piston_nm;
  tip_sum_ += q.theta_x_urad;
  tilt_sum_ += q.theta_y_urad;
  last_ = q;
  lo_ = std::min(lo_, q.piston_nm);
  hi_ = std::max(hi_, q.piston_nm);
}

void ExposureAccumulator::finish(ExposureRecord& rec, bool has_truth, double end_s) const noexcept {
  const double dn = static_cast<double>(std::max<std::size_t>(n_, 1));
  rec.gauge_error_max_nm = std::max(rec.gauge_error_max_nm, error_max_nm_);
  for (double s : error_sum_)
    rec.gauge_error_mean_nm = std::max(rec.gauge_error_mean_nm, std::fabs(s / dn));
  rec.exposure_end_s = end_s;
  rec.has_truth = has_truth;
  if (!has_truth)
    return;
  rec.truth_piston_nm = (piston_sum_ - 0.5 * last_.piston_nm) / dn;
  rec.truth_blur_nm = hi_ - lo_;
  rec.truth_tip_urad = (tip_sum_ - 0.5 * last_.theta_x_urad) / dn;
  rec.truth_tilt_urad = (tilt_sum_ - 0.5 * last_.theta_y_urad) / dn;
}

}  // namespace piezoshift::instrument
