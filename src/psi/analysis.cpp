#include "piezoshift/psi/analysis.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "piezoshift/psi/unwrap.hpp"
#include "piezoshift/psi/zernike.hpp"

namespace piezoshift::psi {

Analysis analyze_frames(std::span<const Map> frames, const Mask& mask, const AnalysisOptions& o) {
  Analysis a;
  a.phase = wrapped_phase(frames, mask, o.phase);
  // drop pixels without modulation
  std::vector<double> mod;
  for (std::size_t p = 0; p < mask.size(); ++p)
    if (mask.v[p] && std::isfinite(a.phase.modulation.v[p]))
      mod.push_back(a.phase.modulation.v[p]);
  if (mod.size() < static_cast<std::size_t>(std::max(o.zernike_terms, 36)))
    throw std::invalid_argument("analysis: too few pixels with fringe modulation");
  const auto mid = mod.begin() + static_cast<std::ptrdiff_t>(mod.size() / 2);
  std::nth_element(mod.begin(), mid, mod.end());
  const double floor = o.min_modulation_fraction * *mid;
  a.valid = Mask(mask.width, mask.height, 0);
  for (std::size_t p = 0; p < mask.size(); ++p)
    a.valid.v[p] =
        mask.v[p] && std::isfinite(a.phase.phase_rad.v[p]) && a.phase.modulation.v[p] >= floor ? 1
                                                                                               : 0;
  if (a.valid.count() < static_cast<std::size_t>(std::max(o.zernike_terms, 36)))
    throw std::invalid_argument("analysis: too few pixels with fringe modulation");
  Map phi = unwrap_phase(a.phase.phase_rad, a.valid);
  const double nm_per_rad = o.wavelength_nm / (4.0 * std::numbers::pi);
  for (double& v : phi.v)
    v *= nm_per_rad;
  a.surface_nm = remove_terms(phi, a.valid, o.removal);
  a.figures = surface_figures(a.surface_nm, a.valid);
  a.zernike_nm = fit_zernike(a.surface_nm, a.valid, o.zernike_terms);
  return a;
}

double surface_error_rms_nm(const Map& measured, const Map& truth, const Mask& mask) {
  Map diff(mask.width, mask.height, std::nan(""));
  Mask both(mask.width, mask.height, 0);
  for (std::size_t p = 0; p < mask.size(); ++p)
    if (mask.v[p] && std::isfinite(measured.v[p]) && std::isfinite(truth.v[p])) {
      diff.v[p] = measured.v[p] - truth.v[p];
      both.v[p] = 1;
    }
  return surface_figures(remove_terms(diff, both, Removal::kTilt), both, false).rms;
}

}  // namespace piezoshift::psi
