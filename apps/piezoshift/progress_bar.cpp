#include "progress_bar.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

#include <fmt/core.h>

namespace piezoshift::app {

ProgressBar::ProgressBar(int stages) : enabled_(isatty(STDERR_FILENO) == 1), stages_(stages) {}

ProgressBar::~ProgressBar() {
  if (enabled_ && stage_ > 0)
    fmt::print(stderr, "\n");
}

void ProgressBar::update(double done, double total, std::string_view label) {
  if (!enabled_)
    return;
  if (label != label_) {
    label_ = label;
    ++stage_;
    last_percent_ = -1;
  }
  const int percent = total > 0 ? std::clamp(static_cast<int>(100.0 * done / total), 0, 100) : 0;
  if (percent == last_percent_)
    return;
  last_percent_ = percent;
  const int width = 30;
  const int filled = percent * width / 100;
  fmt::print(stderr, "\r  [{}/{}] {:<16} [{}{}] {:3d} %", stage_, stages_, label_,
             std::string(static_cast<std::size_t>(filled), '#'),
             std::string(static_cast<std::size_t>(width - filled), ' '), percent);
  std::fflush(stderr);
}

}  // namespace piezoshift::app
