#include "piezoshift/psi/fringe_visibility.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace piezoshift::psi {

namespace {

double quantile(std::vector<double>& v, double q) {
  const auto k = static_cast<std::ptrdiff_t>(std::lround(q * static_cast<double>(v.size() - 1)));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[static_cast<std::size_t>(k)];
}

}  // namespace

FringeVisibility fringe_visibility(const Map& counts, double full_scale_counts, int tile_px,
                                   double dark_fraction) {
  if (tile_px < 2 || counts.width <= 0 || counts.height <= 0)
    throw std::invalid_argument("fringe visibility: tiles of 2 px or more on a non-empty frame");
  const int nx = (counts.width + tile_px - 1) / tile_px;
  const int ny = (counts.height + tile_px - 1) / tile_px;
  FringeVisibility out;
  out.tiles = Map(nx, ny, std::numeric_limits<double>::quiet_NaN());
  std::vector<double> values, judged;
  for (int ty = 0; ty < ny; ++ty)
    for (int tx = 0; tx < nx; ++tx) {
      values.clear();
      for (int j = ty * tile_px; j < std::min(counts.height, (ty + 1) * tile_px); ++j)
        for (int i = tx * tile_px; i < std::min(counts.width, (tx + 1) * tile_px); ++i)
          if (const double c = counts.at(i, j); std::isfinite(c))
            values.push_back(c);
      if (values.size() < 4)
        continue;
      const double lo = quantile(values, 0.02), hi = quantile(values, 0.98);
      if (hi + lo < dark_fraction * full_scale_counts || hi + lo <= 0.0)
        continue;
      const double v = (hi - lo) / (hi + lo);
      out.tiles.at(tx, ty) = v;
      judged.push_back(v);
    }
  out.judged = judged.size();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  out.median = judged.empty() ? nan : quantile(judged, 0.5);
  out.p90 = judged.empty() ? nan : quantile(judged, 0.9);
  return out;
}

}  // namespace piezoshift::psi
