#include "piezoshift/psi/surface_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "piezoshift/psi/zernike.hpp"

namespace piezoshift::psi {
namespace {

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  double sum = 0.0, sum2 = 0.0;
  std::size_t n = 0;
  void add(double v) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
    sum += v;
    sum2 += v * v;
    ++n;
  }
  double rms() const {
    const double m = sum / static_cast<double>(n);
    return std::sqrt(std::max(0.0, sum2 / static_cast<double>(n) - m * m));
  }
};

}  // namespace

Map remove_terms(const Map& surface, const Mask& mask, Removal removal) {
  const int terms = removal == Removal::kPiston ? 1 : removal == Removal::kTilt ? 3 : 4;
  const std::vector<double> c = fit_zernike(surface, mask, terms);
  const Map fit = zernike_surface(c, mask);
  Map out = surface;
  for (std::size_t p = 0; p < out.size(); ++p)
    out.v[p] = mask.v[p] ? surface.v[p] - fit.v[p] : std::nan("");
  return out;
}

SurfaceFigures surface_figures(const Map& surface, const Mask& mask, bool with_pvr) {
  Range r;
  for (std::size_t p = 0; p < surface.size(); ++p)
    if (mask.v[p] && std::isfinite(surface.v[p]))
      r.add(surface.v[p]);
  if (r.n == 0)
    throw std::invalid_argument("surface figures: no valid pixel in the mask");
  SurfaceFigures f;
  f.pixels = r.n;
  f.pv = r.hi - r.lo;
  f.rms = r.rms();
  if (with_pvr && r.n >= 36) {
    const std::vector<double> c = fit_zernike(surface, mask, 36);
    const Map fit = zernike_surface(c, mask);
    Range rf, res;
    for (std::size_t p = 0; p < surface.size(); ++p)
      if (mask.v[p] && std::isfinite(surface.v[p])) {
        rf.add(fit.v[p]);
        res.add(surface.v[p] - fit.v[p]);
      }
    f.pvr = (rf.hi - rf.lo) + 3.0 * res.rms();
  }
  return f;
}

}  // namespace piezoshift::psi
