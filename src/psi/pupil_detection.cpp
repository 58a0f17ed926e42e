#include "piezoshift/psi/pupil_detection.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include <fmt/core.h>

namespace piezoshift::psi {
namespace {

// The temporal standard deviation of the frames at each pixel.
std::vector<double> temporal_std(std::span<const Map> frames) {
  const std::size_t n = frames.front().size();
  const double nf = static_cast<double>(frames.size());
  std::vector<double> m(n);
  for (std::size_t p = 0; p < n; ++p) {
    double s = 0.0, s2 = 0.0;
    for (const Map& f : frames) {
      s += f.v[p];
      s2 += f.v[p] * f.v[p];
    }
    m[p] = std::sqrt(std::max(0.0, s2 / nf - (s / nf) * (s / nf)));
  }
  return m;
}

// 4-connected regions of the pixels where in[p] == value: a label per pixel (-1 elsewhere) and
// each region's size.
std::vector<std::size_t> label_regions(const Mask& in, std::uint8_t value,
                                       std::vector<int>& label) {
  const int w = in.width, h = in.height;
  label.assign(in.size(), -1);
  std::vector<std::size_t> sizes, stack;
  for (std::size_t start = 0; start < in.size(); ++start) {
    if (in.v[start] != value || label[start] >= 0)
      continue;
    const int id = static_cast<int>(sizes.size());
    sizes.push_back(0);
    stack.push_back(start);
    label[start] = id;
    while (!stack.empty()) {
      const std::size_t p = stack.back();
      stack.pop_back();
      ++sizes.back();
      const int i = static_cast<int>(p % static_cast<std::size_t>(w));
      const int j = static_cast<int>(p / static_cast<std::size_t>(w));
      const int ni[4] = {i - 1, i + 1, i, i}, nj[4] = {j, j, j - 1, j + 1};
      for (int e = 0; e < 4; ++e) {
        if (ni[e] < 0 || nj[e] < 0 || ni[e] >= w || nj[e] >= h)
          continue;
        const std::size_t q = static_cast<std::size_t>(nj[e]) * w + ni[e];
        if (in.v[q] == value && label[q] < 0) {
          label[q] = id;
          stack.push_back(q);
        }
      }
    }
  }
  return sizes;
}

// Fills the holes of region (1 inside) that do not touch the frame's border and hold at most
// max_area pixels.
void fill_small_holes(Mask& region, std::size_t max_area) {
  std::vector<int> label;
  const std::vector<std::size_t> sizes = label_regions(region, 0, label);
  std::vector<bool> border(sizes.size(), false);
  const int w = region.width, h = region.height;
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i)
      if (i == 0 || j == 0 || i == w - 1 || j == h - 1)
        if (const int l = label[static_cast<std::size_t>(j) * w + i]; l >= 0)
          border[static_cast<std::size_t>(l)] = true;
  for (std::size_t p = 0; p < region.size(); ++p)
    if (const int l = label[p]; l >= 0 && !border[static_cast<std::size_t>(l)] &&
                                sizes[static_cast<std::size_t>(l)] <= max_area)
      region.v[p] = 1;
}

double median(std::vector<double> v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

double robust_max(const std::vector<double>& m) {
  std::vector<double> v;
  v.reserve(m.size());
  for (double x : m)
    if (std::isfinite(x))
      v.push_back(x);
  if (v.empty())
    return 0.0;
  const auto at = v.begin() + static_cast<std::ptrdiff_t>(0.99 * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), at, v.end());
  return *at;
}

Map modulation_map(std::span<const Map> frames) {
  if (frames.empty() || frames.front().size() == 0)
    throw std::invalid_argument("modulation: no frames, or frames without pixels");
  Map out(frames.front().width, frames.front().height);
  out.v = temporal_std(frames);
  return out;
}

DetectedPupil pupil_from_modulation(std::span<const Map> frames, const PupilDetection& d) {
  if (frames.empty() || frames.front().size() == 0)
    throw std::invalid_argument("pupil: no frames, or frames without pixels");
  const Map& f0 = frames.front();
  const std::vector<double> m = temporal_std(frames);
  DetectedPupil out;
  out.modulation_max = robust_max(m);
  out.threshold = d.fraction * out.modulation_max;
  Mask above(f0.width, f0.height, 0);
  std::size_t n_above = 0;
  for (std::size_t p = 0; p < m.size(); ++p)
    if (out.modulation_max > 0.0 && m[p] >= out.threshold) {
      above.v[p] = 1;
      ++n_above;
    }
  std::vector<int> label;
  const std::vector<std::size_t> sizes = label_regions(above, 1, label);
  const auto largest = std::max_element(sizes.begin(), sizes.end());
  const std::size_t area = largest == sizes.end() ? 0 : *largest;
  if (area < d.min_pixels)
    throw std::invalid_argument(fmt::format(
        "too few pixels with fringe modulation to find the pupil ({} of the {} needed; the "
        "frames' temporal modulation peaks at {:.3g}): identical, blank or too small frames?",
        area, d.min_pixels, out.modulation_max));
  out.share = static_cast<double>(area) / static_cast<double>(n_above);
  if (out.share < d.min_share)
    throw std::invalid_argument(fmt::format(
        "the fringe modulation does not separate a pupil from the background: the largest "
        "region above {:.3g} (a quarter of the modulation's 99th percentile) holds {:.0f} % of "
        "those pixels; give a mask",
        out.threshold, 100.0 * out.share));
  const int id = static_cast<int>(largest - sizes.begin());
  out.mask = Mask(f0.width, f0.height, 0);
  for (std::size_t p = 0; p < label.size(); ++p)
    out.mask.v[p] = label[p] == id ? 1 : 0;
  std::vector<double> in, off;
  for (std::size_t p = 0; p < m.size(); ++p)
    (out.mask.v[p] ? in : off).push_back(m[p]);
  // an outside of at least 1 % of the frame must be much quieter than the pupil (noise alone
  // makes one region too, with an outside about 2.6 x below it)
  out.contrast = off.size() * 100 >= m.size() ? median(in) / std::max(median(off), 1e-300)
                                              : std::numeric_limits<double>::infinity();
  if (out.contrast < d.min_contrast)
    throw std::invalid_argument(fmt::format(
        "the fringe modulation does not separate a pupil from the background: the pupil found "
        "is only {:.2g} x as modulated as the rest of the frame (at least {:g}); give a mask",
        out.contrast, d.min_contrast));
  fill_small_holes(out.mask,
                   static_cast<std::size_t>(d.max_hole_fraction * static_cast<double>(area)));
  return out;
}

}  // namespace piezoshift::psi
