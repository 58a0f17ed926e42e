#include "piezoshift/psi/grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace piezoshift::psi {

std::pair<double, double> finite_range(const Map& map) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double v : map.v)
    if (std::isfinite(v)) {
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  return std::isfinite(lo) ? std::pair{lo, hi} : std::pair{0.0, 0.0};
}

std::size_t Mask::count() const {
  return static_cast<std::size_t>(std::count(v.begin(), v.end(), std::uint8_t{1}));
}

Mask disk_mask(int width, int height, double radius_px) {
  Mask m(width, height, 0);
  const double cx = 0.5 * (width - 1), cy = 0.5 * (height - 1);
  for (int j = 0; j < height; ++j)
    for (int i = 0; i < width; ++i)
      if (std::hypot(i - cx, j - cy) <= radius_px)
        m.v[static_cast<std::size_t>(j) * width + i] = 1;
  return m;
}

Pupil pupil_of(const Mask& mask) {
  double sx = 0.0, sy = 0.0;
  std::size_t n = 0;
  for (int j = 0; j < mask.height; ++j)
    for (int i = 0; i < mask.width; ++i)
      if (mask.v[static_cast<std::size_t>(j) * mask.width + i]) {
        sx += i;
        sy += j;
        ++n;
      }
  if (n == 0)
    throw std::invalid_argument("pupil: the mask is empty");
  Pupil p;
  p.cx = sx / static_cast<double>(n);
  p.cy = sy / static_cast<double>(n);
  double r2 = 0.0;
  for (int j = 0; j < mask.height; ++j)
    for (int i = 0; i < mask.width; ++i)
      if (mask.v[static_cast<std::size_t>(j) * mask.width + i])
        r2 = std::max(r2, (i - p.cx) * (i - p.cx) + (j - p.cy) * (j - p.cy));
  p.radius_px = r2 > 0.0 ? std::sqrt(r2) : 1.0;
  return p;
}

}  // namespace piezoshift::psi
