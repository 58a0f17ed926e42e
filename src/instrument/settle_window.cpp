#include "piezoshift/instrument/settle_window.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

namespace piezoshift::instrument {

SettleWindow::SettleWindow(const psi::OnTarget& criterion, double period_s)
    : criterion_(criterion) {
  const auto hold = std::max(1L, std::lround(criterion.hold_s / period_s));
  window_.resize(static_cast<std::size_t>(hold));
}

void SettleWindow::reset() noexcept {
  filled_ = 0;
  next_ = 0;
}

bool SettleWindow::add(const std::array<double, 3>& error_nm) noexcept {
  window_[next_] = error_nm;
  next_ = (next_ + 1) % window_.size();
  filled_ = std::min(filled_ + 1, window_.size());
  return filled_ == window_.size() && worst_mean_nm() <= criterion_.band_nm;
}

double SettleWindow::worst_mean_nm() const noexcept {
  if (filled_ == 0)
    return 0.0;
  double worst = 0.0;
  for (std::size_t i = 0; i < 3; ++i) {
    double sum = 0.0;
    for (std::size_t k = 0; k < filled_; ++k)
      sum += window_[k][i];
    worst = std::max(worst, std::fabs(sum / static_cast<double>(filled_)));
  }
  return worst;
}

std::string SettleWindow::timeout_reason(double t_s) const {
  return fmt::format("the stage did not settle within {} nm (mean over {} s) in {} s at {:.3f} s",
                     criterion_.band_nm, criterion_.hold_s, criterion_.timeout_s, t_s);
}

}  // namespace piezoshift::instrument
