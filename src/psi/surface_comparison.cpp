#include "piezoshift/psi/surface_comparison.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/core.h>

#include "piezoshift/psi/surface_metrics.hpp"
#include "piezoshift/psi/zernike.hpp"

namespace piezoshift::psi {

SurfaceComparison compare_surfaces(const Map& a, const Map& b, int zernike_terms) {
  if (a.width != b.width || a.height != b.height)
    throw std::invalid_argument(fmt::format("the maps are {} x {} and {} x {} pixels", a.width,
                                            a.height, b.width, b.height));
  SurfaceComparison c;
  c.common = Mask(a.width, a.height, 0);
  c.difference_nm = Map(a.width, a.height, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t p = 0; p < a.size(); ++p) {
    if (std::isfinite(a.v[p]) && std::isfinite(b.v[p])) {
      c.common.v[p] = 1;
      c.difference_nm.v[p] = b.v[p] - a.v[p];
      ++c.pixels;
    }
  }
  if (c.pixels < static_cast<std::size_t>(std::max(zernike_terms, 3)))
    throw std::invalid_argument(
        fmt::format("{} pixels hold a value in both maps, {} are needed for the fit", c.pixels,
                    std::max(zernike_terms, 3)));
  c.rms_nm = surface_figures(c.difference_nm, c.common, false).rms;
  c.pv_nm = surface_figures(c.difference_nm, c.common, false).pv;
  c.rms_tilt_removed_nm =
      surface_figures(remove_terms(c.difference_nm, c.common, Removal::kTilt), c.common, false).rms;
  c.zernike_a_nm = fit_zernike(a, c.common, zernike_terms);
  c.zernike_b_nm = fit_zernike(b, c.common, zernike_terms);
  c.zernike_difference_nm = fit_zernike(c.difference_nm, c.common, zernike_terms);
  return c;
}

}  // namespace piezoshift::psi
